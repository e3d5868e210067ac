"""Evaluation throughput: episodes per minute, inline vs process pool vs Ray (local).

One JSON object per measurement on stdout. The episode function is selectable by dotted path
(default: the fake 0.15 s episode of the tests; point it at the oracle episode for real figures):

    python benchmarks/eval_throughput.py --episode-fn more_agent.eval.episode:run_episode \
        --tasks more-paper --episodes 40 --workers 1 2 4 --backends inline processes ray
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))  # Ray workers

from more_agent.eval.harness import evaluate, resolve_tasks  # noqa: E402
from more_agent.eval.store import RunConfig  # noqa: E402


def measure(backend: str, workers: int, tasks: list[str], seeds: int, episode_fn: str, planner: str) -> dict:
    """Run one evaluation into a temporary directory and time it."""
    config = RunConfig(
        planner=planner,
        tasks=tasks,
        seeds=list(range(seeds)),
        episode_fn=episode_fn,
        workers=workers if backend == "processes" else 1,
        ray_address="local" if backend == "ray" else None,
    )
    with tempfile.TemporaryDirectory() as d:
        if backend == "ray":
            import ray

            ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
        start = time.perf_counter()
        records = evaluate(config, Path(d) / "run", show_progress=False)
        seconds = time.perf_counter() - start
        if backend == "ray":
            ray.shutdown()
    return {
        "benchmark": "eval_throughput",
        "backend": backend,
        "workers": workers if backend != "inline" else 1,
        "episodes": len(records),
        "errors": sum(r.error is not None for r in records),
        "seconds": round(seconds, 3),
        "episodes_per_minute": round(60 * len(records) / seconds, 1),
        "episode_fn": episode_fn,
        "cpu_count": os.cpu_count(),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episode-fn", default="tests.eval.fake_episodes:slow_episode")
    p.add_argument("--tasks", default=None, help="--tasks of more-agent eval (default: synthetic names)")
    p.add_argument("--episodes", type=int, default=24, help="synthetic task count when --tasks is not given")
    p.add_argument("--seeds", type=int, default=1)
    p.add_argument("--planner", default="oracle")
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    p.add_argument("--backends", nargs="+", default=["inline", "processes", "ray"], choices=["inline", "processes", "ray"])
    a = p.parse_args()
    tasks = resolve_tasks(a.tasks) if a.tasks else [f"task{i}" for i in range(a.episodes)]
    for backend in a.backends:
        # one worker means inline in the harness, so the process pool is measured from two workers up
        counts = [1] if backend == "inline" else [w for w in a.workers if backend == "ray" or w > 1]
        for workers in counts:
            print(json.dumps(measure(backend, workers, tasks, a.seeds, a.episode_fn, a.planner)), flush=True)


if __name__ == "__main__":
    main()
