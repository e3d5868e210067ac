"""``more-agent scene ...``: list, generate, render scenes. (Owned by the scenes work.)"""

import typer

app = typer.Typer(help="BEHAVIOR-1K scenes: list, generate, render.", no_args_is_help=True)
