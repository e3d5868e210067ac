"""How hard the benchmark worlds are: one JSON line per (task, seed) world, then one summary line.

``python benchmarks/world_stats.py [--tasks more-paper] [--seeds 3] [--start random|task-room]``

Each world is instantiated as an episode would be (scene drawn with the seed, the scene's own
objects, the start pose) and described by the episode record's ``WorldStats``: objects (furniture,
doors and items), task objects, distractors, start room, task rooms, ``start_to_task_m`` (path
on the true map, doors open, to the nearest pose from which a task object is within reach) and the
goal's furniture the description cannot single out (``ambiguous_scopes``). The summary gives objects
and distractors per world (median, max, and per scene type), the share of worlds whose robot starts
outside every task room (overall and per scene type), the worlds with an ambiguous goal instance,
the ``start_to_task_m`` distribution, the scenes used per task and the instantiation time. No
planner runs.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections import defaultdict

from more_agent.errors import UserError
from more_agent.eval.episode import world_stats
from more_agent.sim.instantiate import instantiate
from more_agent.sim.tasks import task_set

SCENE_TYPES = ("grocery_store", "office", "restaurant", "school", "hotel", "hall", "house")
"""Scene name prefixes grouped in the summary; every other scene (``Rs_int``, ``Beechwood_0_garden``,
``gates_bedroom``) is a home and counts as ``house``."""


def scene_type(scene: str) -> str:
    """'grocery_store_cafe' -> 'grocery_store'; 'Rs_int' -> 'house'."""
    return next((t for t in SCENE_TYPES if scene.startswith(t)), "house")


def _quantiles(values: list[float]) -> dict[str, float]:
    if not values:
        return {}
    q = statistics.quantiles(values, n=10) if len(values) > 1 else [values[0]] * 9
    return {"min": round(min(values), 2), "p10": round(q[0], 2), "median": round(statistics.median(values), 2),
            "p90": round(q[8], 2), "max": round(max(values), 2)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", default="more-paper", help="task set: more-paper or behavior-rearrange")
    parser.add_argument("--seeds", type=int, default=3, help="seeds 0 .. N-1 per task")
    parser.add_argument("--start", default="random", help="random (default) or task-room")
    args = parser.parse_args()

    rows: list[dict] = []
    failures = 0
    for task in task_set(args.tasks):
        for seed in range(args.seeds):
            t = time.perf_counter()
            try:
                instance = instantiate(task, seed=seed, start=args.start)
            except UserError as e:
                failures += 1
                print(json.dumps({"task": task, "seed": seed, "error": str(e)}), flush=True)
                continue
            stats = world_stats(instance)
            row = {"task": task, "seed": seed, "scene": instance.scene, **stats.model_dump(),
                   "outside_task_rooms": stats.start_room not in stats.task_rooms,
                   "instantiate_s": round(time.perf_counter() - t, 3)}
            rows.append(row)
            print(json.dumps(row), flush=True)

    by_type: dict[str, list[dict]] = defaultdict(list)
    scenes_per_task: dict[str, set[str]] = defaultdict(set)
    for r in rows:
        by_type[scene_type(r["scene"])].append(r)
        scenes_per_task[r["task"]].add(r["scene"])
    distances = [r["start_to_task_m"] for r in rows if r["start_to_task_m"] is not None]
    n_scenes = [len(s) for s in scenes_per_task.values()]
    print(json.dumps({
        "summary": args.tasks, "seeds": args.seeds, "start": args.start, "worlds": len(rows), "not_instantiated": failures,
        "objects": _quantiles([r["objects"] for r in rows]),
        "distractors": _quantiles([r["distractors"] for r in rows]),
        "per_scene_type": {
            t: {"worlds": len(rs), "objects_median": statistics.median(r["objects"] for r in rs),
                "objects_min": min(r["objects"] for r in rs), "objects_max": max(r["objects"] for r in rs),
                "distractors_median": statistics.median(r["distractors"] for r in rs),
                "start_outside_task_rooms": round(sum(r["outside_task_rooms"] for r in rs) / len(rs), 3),
                "ambiguous_goal_worlds": sum(bool(r["ambiguous_scopes"]) for r in rs)}
            for t, rs in sorted(by_type.items())
        },
        "start_outside_task_rooms": round(sum(r["outside_task_rooms"] for r in rows) / max(len(rows), 1), 3),
        "ambiguous_goal_worlds": sum(bool(r["ambiguous_scopes"]) for r in rows),
        "start_to_task_m": _quantiles(distances),
        "unreachable_starts": len(rows) - len(distances),
        "scenes_used": len({r["scene"] for r in rows}),
        "scenes_per_task": {"median": statistics.median(n_scenes) if n_scenes else 0, "max": max(n_scenes, default=0)},
        "instantiate_s": _quantiles([r["instantiate_s"] for r in rows]),
    }), flush=True)


if __name__ == "__main__":
    main()
