"""``more-agent tasks ...``: list and show tasks. (Owned by the tasks work.)"""

import typer

app = typer.Typer(help="BEHAVIOR-1K activities: list task sets, show one task.", no_args_is_help=True)
