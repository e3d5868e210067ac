"""The ``more-agent`` command: ``run | eval | tasks | scene | report | view | ingest | plan | serve``.

Each command group lives in ``more_agent.commands.<name>``; this module only assembles them and
turns a ``UserError`` into one message and exit status 2, never a traceback.
"""

from __future__ import annotations

import typer

from more_agent.commands import eval as eval_cmd
from more_agent.commands import ingest as ingest_cmd
from more_agent.commands import plan as plan_cmd
from more_agent.commands import report as report_cmd
from more_agent.commands import run as run_cmd
from more_agent.commands import scene as scene_cmd
from more_agent.commands import serve as serve_cmd
from more_agent.commands import tasks as tasks_cmd
from more_agent.commands import view as view_cmd

app = typer.Typer(
    name="more-agent",
    help="MORE: mobile manipulation rearrangement with grounded language reasoning, on an embedded BEHAVIOR-1K world.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
app.command("run")(run_cmd.run)
app.command("eval")(eval_cmd.eval_)
app.command("report")(report_cmd.report)
app.command("view")(view_cmd.view)
app.command("ingest")(ingest_cmd.ingest)
app.command("plan")(plan_cmd.plan)
app.command("serve")(serve_cmd.serve)
app.add_typer(tasks_cmd.app, name="tasks")
app.add_typer(scene_cmd.app, name="scene")
