"""Episode viewer and comparison report: time to write them and their size.

1. A 50-step MORE episode with frames: MORE against a scripted LLM that explores every step (the fake
   OpenAI server of the tests, through the real client) in a large scene, run with ``viewer=True``
   (frames and scene graphs saved). Then ``write_viewer`` is timed (median of ``--repeats``) and
   the page's size printed. Targets: under 2 s and 5 MB.
2. ``write_reports`` for 165 episodes (3 systems x the 55 ``more-paper`` tasks). Every record is
   that 50-step episode's record under another task / system with a varied outcome (the longest
   action trace an episode can have, so an upper bound on the page), and every episode folder holds
   its map.png and viewer.html. Target: report.html under 2 MB.

One JSON object per measurement on stdout::

    python benchmarks/viewer.py [--scene Beechwood_0_garden] [--repeats 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
import time
import zlib
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from more_agent.eval.episode_folder import MAP_FILE, VIEWER_FILE  # noqa: E402
from more_agent.eval.report import SourcedRecord  # noqa: E402
from more_agent.eval.report_writer import write_reports  # noqa: E402
from more_agent.eval.store import EPISODE_DIRS, EpisodeWriter, episode_dirname  # noqa: E402
from more_agent.eval.viewer import run_episode_with_viewer, write_viewer  # noqa: E402
from more_agent.llm import LLMConfig, make_client  # noqa: E402
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner  # noqa: E402
from more_agent.records import EpisodeRecord, EpisodeSpec, Failure, LLMUsage  # noqa: E402
from more_agent.sim.tasks import task_set  # noqa: E402
from tests.planners.brain import BrainServer, parse_prompt, plan  # noqa: E402

TASK = "putting_shopping_away"


def explorer(body: dict[str, Any]) -> str:
    """A scripted LLM that labels every room a living room, keeps every room in the filter and explores."""
    system, user = body["messages"][0]["content"], body["messages"][-1]["content"]
    if "Possible room types" in user:
        return json.dumps({"room": "living_room"})
    scene = parse_prompt(user)
    if "Remove every object" in system:
        return json.dumps({"rooms": [{"room": r, "objects": sorted(o)[:3]} for r, o in scene.rooms.items()]})
    rooms = scene.unexplored or list(scene.rooms)
    return plan("explore", rooms[len(body["messages"]) % len(rooms)])


def fifty_step_episode(out: Path, scene: str) -> EpisodeRecord:
    """Run the exploring MORE episode (50 high-level steps unless exploring runs out) with viewer files."""
    with BrainServer(explorer) as server:
        config = LLMConfig(base_url=server.base_url, api_key="sk-bench", timeout_s=10, max_retries=0,
                           cache_path=out.parent / "cache.sqlite")
        client = make_client("openai:scripted", config)
        planner = LLMPlanner(PLANNER_CONFIGS["more"], LLMClients(client, client, "openai:scripted"))
        # Started in the task room: the scripted explorer never opens doors, and a random start behind
        # closed doors would leave it nothing to explore (a short, unrepresentative page).
        spec = EpisodeSpec(task=TASK, scene=scene, seed=0, planner="more", llm="openai:scripted", start="task-room")
        return run_episode_with_viewer(spec, planner=planner, out_dir=out)


def comparison_runs(root: Path, record: EpisodeRecord, episode_dir: Path) -> list[SourcedRecord]:
    """165 records (3 systems x 55 tasks) shaped like ``record``, each with its episode folder's map and viewer."""
    sourced = []
    systems = [("oracle", None), ("more", "openai:gpt-4o"), ("moma-llm", "openai:gpt-4o")]
    causes = ["never_observed", "unreachable", "subpolicy_failure", "done_early", "step_limit"]
    for k, (planner, llm) in enumerate(systems):
        run = root / planner
        (run / EPISODE_DIRS).mkdir(parents=True)
        with EpisodeWriter(run / "episodes.jsonl") as w:
            for i, task in enumerate(task_set("more-paper")):
                h = zlib.crc32(f"{task}|{planner}".encode())
                ok = h % 10 < (9, 5, 3)[k]
                r = record.model_copy(update={
                    "task": task, "planner": planner, "llm": llm, "success": ok, "all_goals_met": ok, "error": None,
                    "task_progress": 1.0 if ok else (h >> 4) % 4 / 4, "high_level_steps": 8 + (h >> 8) % 43,
                    "failure": None if ok else Failure(cause=causes[(h >> 12) % len(causes)], detail="synthetic"),
                    "llm_usage": LLMUsage() if llm is None else LLMUsage(
                        calls=40 + i % 30, prompt_tokens=40_000 + 997 * i, completion_tokens=2_000 + 31 * i),
                })
                folder = run / EPISODE_DIRS / episode_dirname(r.task, r.scene, r.seed, r.planner)
                folder.mkdir()
                for name in (MAP_FILE, VIEWER_FILE):
                    shutil.copy(episode_dir / name, folder / name)
                w.append(r)
                sourced.append(SourcedRecord(r, run))
    return sourced


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="Beechwood_0_garden", help="Scene of the 50-step episode.")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--keep", type=Path, help="Write everything into this (new) folder and keep it.")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as d:
        root = Path(args.keep or d)
        t = time.perf_counter()
        record = fifty_step_episode(root / "ep", args.scene)
        episode_s = time.perf_counter() - t
        times = []
        for _ in range(args.repeats):
            t = time.perf_counter()
            page = write_viewer(root / "ep")
            times.append(time.perf_counter() - t)
        frames = len(list((root / "ep" / "frames").glob("*_rgb.png")))
        print(json.dumps({
            "measure": "viewer", "steps": record.high_level_steps, "frames_rendered": frames,
            "llm_calls": record.llm_usage.calls, "episode_s": round(episode_s, 2),
            "write_viewer_s_median": round(statistics.median(times), 3), "viewer_mb": round(page.stat().st_size / 1e6, 3),
            "targets": {"write_viewer_s": 2.0, "viewer_mb": 5.0},
        }), flush=True)
        sourced = comparison_runs(root / "runs", record, root / "ep")
        t = time.perf_counter()
        paths = write_reports(sourced, root / "compare", title="165 episodes")
        report_s = time.perf_counter() - t
        sizes = {p.name: p.stat().st_size for p in paths}
        print(json.dumps({
            "measure": "report", "episodes": len(sourced), "write_reports_s": round(report_s, 2),
            "report_html_mb": round(sizes["report.html"] / 1e6, 3),
            "plots_mb": round(sum(v for k, v in sizes.items() if k.endswith(".png")) / 1e6, 3),
            "targets": {"report_html_mb": 2.0},
        }), flush=True)


if __name__ == "__main__":
    main()
