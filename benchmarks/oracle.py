"""Benchmark: the oracle planner over a task set, one seed each.

Prints one JSON object per episode (task, scene, success, progress, steps, seconds, error) and a
final summary object (episodes, instantiated, successes, success rate over instantiated tasks,
wall seconds). Run: ``python benchmarks/oracle.py [--tasks more-paper] [--seed 0] [--limit N]``.
An episode whose task cannot be instantiated counts as 'not instantiated', not as an oracle failure.
"""

from __future__ import annotations

import argparse
import json
import time

from more_agent.eval.episode import run_episode
from more_agent.records import EpisodeSpec
from more_agent.sim.instantiate import InstantiationError
from more_agent.sim.tasks import task_set


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", default="more-paper", help="task set: more-paper or behavior-rearrange")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit", type=int, default=None, help="only the first N tasks")
    args = parser.parse_args()

    names = task_set(args.tasks)[: args.limit]
    start = time.perf_counter()
    instantiated = successes = 0
    for task in names:
        t = time.perf_counter()
        try:
            record = run_episode(EpisodeSpec(task=task, seed=args.seed), strict=True)
        except InstantiationError as e:
            print(json.dumps({"task": task, "instantiated": False, "error": str(e)}), flush=True)
            continue
        instantiated += 1
        successes += record.success
        print(json.dumps({
            "task": task, "scene": record.scene, "instantiated": True, "success": record.success,
            "progress": round(record.task_progress, 3), "high_level_steps": record.high_level_steps,
            "low_level_steps": record.low_level_steps, "seconds": round(time.perf_counter() - t, 3),
            "termination": record.termination, "gave_up": record.gave_up, "error": record.error,
        }), flush=True)
    print(json.dumps({
        "summary": True, "task_set": args.tasks, "seed": args.seed, "episodes": len(names),
        "instantiated": instantiated, "successes": successes,
        "success_rate": round(successes / instantiated, 4) if instantiated else None,
        "wall_seconds": round(time.perf_counter() - start, 2),
    }), flush=True)


if __name__ == "__main__":
    main()
