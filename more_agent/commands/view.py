"""``more-agent view EPISODE_DIR``: write the episode viewer, one self-contained HTML file, or (``--rerun``) a Rerun recording."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from more_agent.commands._common import err_console, user_errors_exit_2


@user_errors_exit_2
def view(
    episode_dir: Annotated[
        Path, typer.Argument(help="Episode folder written by 'more-agent run' or 'eval' (holds episode.json).")
    ],
    out: Annotated[Path | None, typer.Option(help="HTML file to write (default: EPISODE_DIR/viewer.html).")] = None,
    rerun: Annotated[
        Path | None,
        typer.Option(
            help="Write a Rerun recording (.rrd) instead of the page: frames, voxel map, path, scene graph, actions "
            "('rerun' extra)."
        ),
    ] = None,
) -> None:
    """Write an HTML page that steps through the episode: frames, map, scene text, LLM requests and answers
    (or, with --rerun, a Rerun recording of it)."""
    if rerun is not None:
        from more_agent.commands._common import check_output_file
        from more_agent.eval.rerun_export import write_rerun

        check_output_file(rerun)
        summary = write_rerun(episode_dir, rerun)
        err_console.print(
            f"wrote {rerun}: {summary.steps} steps, {summary.frames} frames, {summary.graphs} scene graphs "
            "(open it with: rerun FILE)",
            highlight=False,
            soft_wrap=True,
        )
        return
    from more_agent.eval.viewer import write_viewer

    path = write_viewer(episode_dir, out)
    err_console.print(
        f"wrote {path} (open it in a browser; left/right arrow keys move between steps)",
        highlight=False,
        soft_wrap=True,
    )
