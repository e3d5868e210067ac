"""What one episode costs without an LLM: wall and CPU seconds in all and per phase, per high-level step.

One JSON object per episode on stdout. ``--profile N`` also prints, on stderr, the N functions with the
most CPU time of their own (cProfile with a CPU clock): where the time goes. The numba kernels are
compiled (or loaded from their cache) by a short warm-up episode first, unless ``--no-warmup``.

    python benchmarks/episode_cost.py buy_dog_food --seed 0 [--planner grounded] [--profile 25]
    python benchmarks/episode_cost.py --tasks more-paper --seed 0     # every paper task, one line each
"""

from __future__ import annotations

import argparse
import cProfile
import json
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from more_agent.eval.episode import run_episode  # noqa: E402
from more_agent.eval.harness import resolve_tasks  # noqa: E402
from more_agent.records import EpisodeSpec  # noqa: E402

KITCHEN = Path(__file__).resolve().parents[1] / "tests" / "fixtures" / "tasks_kitchen_scene.json"


def measure(spec: EpisodeSpec, profile: int = 0) -> dict[str, object]:
    """Run one episode into a temporary folder; its wall and CPU time, phases and steps."""
    prof = cProfile.Profile(time.process_time) if profile else None
    with tempfile.TemporaryDirectory() as d:
        t0, c0 = time.perf_counter(), time.process_time()
        if prof is not None:
            prof.enable()
        record = run_episode(spec, out_dir=Path(d))
        if prof is not None:
            prof.disable()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    if prof is not None:
        pstats.Stats(prof, stream=sys.stderr).sort_stats("tottime").print_stats(profile)
    steps = max(record.high_level_steps, 1)
    return {
        "benchmark": "episode_cost", "task": spec.task, "scene": record.scene, "seed": spec.seed, "planner": spec.planner,
        "success": record.success, "error": record.error, "high_level_steps": record.high_level_steps,
        "low_level_steps": record.low_level_steps, "wall_s": round(wall, 3), "cpu_s": round(cpu, 3),
        "cpu_s_per_step": round(cpu / steps, 4), "phases_wall_s": {k: round(v, 3) for k, v in record.timings.items()},
        "profiled": bool(profile),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("task", nargs="?", default="buy_dog_food")
    p.add_argument("--tasks", default=None, help="a task set instead of one task (e.g. more-paper)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--planner", default="grounded")
    p.add_argument("--profile", type=int, default=0, metavar="N", help="print the N costliest functions (stderr)")
    p.add_argument("--no-warmup", action="store_true")
    a = p.parse_args()
    if not a.no_warmup:
        with tempfile.TemporaryDirectory() as d:
            run_episode(EpisodeSpec(task="putting_shopping_away", scene=str(KITCHEN), seed=0, planner="grounded"),
                        out_dir=Path(d))
    tasks = resolve_tasks(a.tasks) if a.tasks else [a.task]
    for task in tasks:
        spec = EpisodeSpec(task=task, seed=a.seed, planner=a.planner)
        print(json.dumps(measure(spec, a.profile)), flush=True)


if __name__ == "__main__":
    main()
