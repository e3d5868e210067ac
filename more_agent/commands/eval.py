"""``more-agent eval``: run a planner over a task set into DIR, resumable; then write DIR's reports."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from more_agent.commands._common import (
    EXIT_FAILED,
    EXIT_RETRYABLE,
    MAX_SEEDS,
    MAX_TRIALS,
    DescriptionsOption,
    DistractorsOption,
    HistoryOption,
    PerceptionOption,
    RoomLLMOption,
    SensingOption,
    StartOption,
    episodes_exit_status,
    err_console,
    use_room_llm,
    user_errors_exit_2,
)
from more_agent.errors import UserError
from more_agent.sensing_spec import DEFAULT_SENSING

RAY_ADDRESS = re.compile(r"local|auto|(ray://)?[A-Za-z0-9.\-\[\]:]+:\d{1,5}")
"""What ``--ray-address`` may be: 'local', 'auto', or HOST:PORT with an optional ray:// prefix."""


@user_errors_exit_2
def eval_(
    tasks: Annotated[str, typer.Option(help="Task set (more-paper, behavior-rearrange), a file of names, or 'a,b,c'.")],
    planner: Annotated[
        str, typer.Option(help="Planner name, e.g. oracle, more, moma-llm, moma-llm-sr, bumble, bumble-filter.")
    ],
    out: Annotated[Path, typer.Option(help="Run directory (episodes.jsonl, run.json, reports).")],
    llm: Annotated[str | None, typer.Option(help="LLM spec, e.g. 'openai:gpt-4o'.")] = None,
    room_llm: RoomLLMOption = None,
    seeds: Annotated[int, typer.Option(min=1, max=MAX_SEEDS, help="Seeds per task: 0 .. N-1.")] = 1,
    trials: Annotated[
        int,
        typer.Option(
            min=1, max=MAX_TRIALS, help="Trials of every task and seed, run in sequence (records carry the trial)."
        ),
    ] = 1,
    long_term_memory: Annotated[
        bool,
        typer.Option(
            help="Give each trial the failure summaries of its world's earlier trials (BUMBLE's --add_past; "
            "only BUMBLE planners keep them)."
        ),
    ] = False,
    scene: Annotated[
        str | None,
        typer.Option(help="Scene for every task (default: drawn per episode among each task's suitable scenes)."),
    ] = None,
    start: StartOption = "random",
    distractors: DistractorsOption = True,
    descriptions: DescriptionsOption = "named",
    history: HistoryOption = "paper",
    perception: PerceptionOption = "gt",
    sensing: SensingOption = DEFAULT_SENSING,
    workers: Annotated[int, typer.Option(min=1, help="Local worker processes.")] = 1,
    ray_address: Annotated[
        str | None, typer.Option(help="Run on Ray: 'local', 'auto' or a cluster address (needs more-agent[ray]).")
    ] = None,
    resume: Annotated[bool, typer.Option(help="Continue the run in OUT: run only the missing episodes.")] = False,
    retry_errors: Annotated[
        bool, typer.Option(help="With --resume: also re-run the episodes that ended with a retryable error.")
    ] = False,
    allow_mixed: Annotated[
        bool, typer.Option(help="With --resume: allow another planner, LLM, task list or seeds than the run in OUT.")
    ] = False,
    max_llm_calls: Annotated[
        int | None, typer.Option(min=1, help="Limit on concurrent LLM calls across all workers.")
    ] = None,
    max_retries: Annotated[int, typer.Option(min=0, help="Re-runs of an episode whose worker died.")] = 2,
    episode_fn: Annotated[str | None, typer.Option(help="Episode function 'module:function' (advanced).")] = None,
    progress: Annotated[bool, typer.Option(help="Show the progress bar.")] = True,
    viewer: Annotated[
        bool,
        typer.Option(
            "--viewer", help="Save frames and maps and write each episode's viewer.html (linked from report.html)."
        ),
    ] = False,
) -> None:
    """Evaluate a planner over a task set; one JSON line per episode in OUT/episodes.jsonl.

    Exit status 0 when every episode of the run ran (whatever it scored), 1 when some ended in a
    system error, 75 when the only such errors are transient (re-run them with --resume
    --retry-errors), 2 for bad input.
    """
    from more_agent import __version__
    from more_agent.eval.harness import DEFAULT_EPISODE_FN, VIEWER_EPISODE_FN, check_task_names, evaluate, resolve_tasks
    from more_agent.eval.report import has_trials, llm_markdown, load_runs, table_i_markdown, trials_markdown
    from more_agent.eval.report_writer import write_reports
    from more_agent.eval.store import RunConfig, check_run_dir
    from more_agent.llm import parse_llm_spec
    from more_agent.llm.prompts import check_history
    from more_agent.perception_spec import parse_perception
    from more_agent.sensing_spec import parse_sensing
    from more_agent.sim.descriptions import check_description_mode
    from more_agent.sim.start_modes import check_start
    from more_agent.sim.tasks import check_scene_suits

    if viewer and episode_fn is not None:
        raise UserError("--viewer runs its own episode function: give either --viewer or --episode-fn")
    if viewer:
        episode_fn = VIEWER_EPISODE_FN
    check_run_dir(out)
    if ray_address is not None and not RAY_ADDRESS.fullmatch(ray_address):
        raise UserError(
            f"--ray-address {ray_address!r} is not 'local', 'auto' or HOST:PORT (e.g. ray://10.0.0.5:10001)"
        )
    if llm is not None:
        parse_llm_spec(llm)  # a bad spec or one holding credentials fails here
    use_room_llm(room_llm)
    names = resolve_tasks(tasks)
    check_start(start)
    check_description_mode(descriptions)
    history_mode = check_history(history)
    perception_mode = parse_perception(perception).text()
    sensing_cadence = parse_sensing(sensing).text()
    if episode_fn in (
        None,
        VIEWER_EPISODE_FN,
    ):  # the real episode functions run BEHAVIOR-1K activities: check everything now
        from more_agent.planners.base import make_planner
        from more_agent.sim.scenes import get_scene

        check_task_names(names)
        if scene is not None:
            get_scene(scene)  # an unknown scene fails with the closest names
            for name in names:
                check_scene_suits(name, scene)
        make_planner(planner, llm)  # an unknown planner or a missing LLM fails here, before any episode
    config = RunConfig(
        planner=planner,
        llm=llm,
        tasks=names,
        seeds=list(range(seeds)),
        scene=scene,
        start=start,
        distractors=distractors,
        descriptions=descriptions,
        history=history_mode,
        perception=perception_mode,
        sensing=sensing_cadence,
        trials=trials,
        long_term_memory=long_term_memory,
        episode_fn=episode_fn or DEFAULT_EPISODE_FN,
        workers=workers,
        ray_address=ray_address,
        more_agent_version=__version__,
    )
    records = evaluate(
        config,
        out,
        resume=resume,
        retry_errors=retry_errors,
        allow_mixed=allow_mixed,
        max_concurrent_llm=max_llm_calls,
        max_retries=max_retries,
        show_progress=progress,
    )
    sourced, _ = load_runs([out])
    paths = write_reports(sourced, out, title=f"{planner} on {tasks}")
    done = [s.record for s in sourced]
    typer.echo(table_i_markdown(done))
    if has_trials(done):
        typer.echo("\n" + trials_markdown(done))
    if any(r.llm for r in done):
        typer.echo("\n" + llm_markdown(done))
    errors = sum(r.error is not None for r in records)
    if errors:
        err_console.print(
            f"{errors} episode(s) ended with an error; see {out / 'report.html'}",
            style="yellow",
            highlight=False,
            markup=False,
        )
    err_console.print("wrote " + ", ".join(str(p) for p in paths), highlight=False, markup=False, soft_wrap=True)
    status = episodes_exit_status(records)
    if status == EXIT_FAILED:
        err_console.print(
            "some episodes ended in a system error (code raised, the LLM refused the request or the key); "
            f"see their 'error' in {out / 'episodes.jsonl'} (exit status {EXIT_FAILED})",
            style="yellow",
            highlight=False,
            markup=False,
        )
    elif status == EXIT_RETRYABLE:
        err_console.print(
            f"{sum(r.retryable for r in records)} episode(s) hit a transient error (LLM transport, worker death) and "
            f"are not results: re-run them with: more-agent eval ... --out {out} --resume --retry-errors "
            f"(exit status {EXIT_RETRYABLE})",
            style="yellow",
            highlight=False,
            markup=False,
        )
    if status:
        raise typer.Exit(code=status)
