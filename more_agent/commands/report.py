"""``more-agent report DIR [DIR ...]``: merge evaluation runs into one comparison table."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from more_agent.commands._common import (
    JsonOption,
    err_console,
    print_json,
    user_errors_exit_2,
)


@user_errors_exit_2
def report(
    run_dirs: Annotated[list[Path], typer.Argument(help="Run directories written by 'more-agent eval'.")],
    out: Annotated[
        Path | None,
        typer.Option(help="Also write summary.md, summary.csv, report.html and the comparison plots (PNG) here."),
    ] = None,
    per_task: Annotated[bool, typer.Option(help="Print the per-task table too.")] = False,
    as_json: JsonOption = False,
) -> None:
    """Print Table I (SR / TTC / TP / rTP with 95% intervals) over the merged runs."""
    from more_agent.eval.metrics import by_system, by_task
    from more_agent.eval.report import load_runs, per_task_markdown, table_i_markdown
    from more_agent.eval.report_writer import write_reports

    sourced, dropped = load_runs(run_dirs)
    records = [s.record for s in sourced]
    if as_json:
        print_json(
            {
                "systems": [{"system": k, **s.model_dump()} for k, s in by_system(records).items()],
                "tasks": [{"system": k, "task": t, **s.model_dump()} for (k, t), s in by_task(records).items()]
                if per_task
                else [],
                "dropped_duplicates": dropped,
            }
        )
    else:
        typer.echo(table_i_markdown(records))
        if per_task:
            typer.echo("\n" + per_task_markdown(records))
    if dropped:
        err_console.print(f"[yellow]{dropped} duplicate episode(s) dropped (the first run listed wins)[/]")
    if out is not None:
        paths = write_reports(sourced, out, title="Comparison of " + ", ".join(str(d) for d in run_dirs))
        err_console.print("wrote " + ", ".join(str(p) for p in paths), highlight=False, markup=False, soft_wrap=True)
