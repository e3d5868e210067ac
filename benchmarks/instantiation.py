"""Instantiation time per task: one JSON object per task, then one summary object.

``python benchmarks/instantiation.py [--set more-paper|behavior-rearrange] [--seed N]``

Per task: ``cold_s`` is the first ``instantiate`` call in this process for the task (bddl parse of
the activity not yet cached; the scene plan may be cached by an earlier task, ``scene_s`` says how
long it took here), ``warm_s`` a second call (parse and scene cached; ``warm_cpu_s`` its CPU time,
the figure to read on a shared machine), ``warm_instantiate_s`` the placement work alone (the
scene's own objects and the start pose included). The summary gives median / max of each.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from more_agent.errors import UserError
from more_agent.sim.instantiate import instantiate
from more_agent.sim.tasks import task_set


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--set", default="more-paper", dest="set_")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rows = []
    for task in task_set(args.set_):
        t0 = time.perf_counter()
        try:
            cold = instantiate(task, seed=args.seed)
        except UserError as e:
            print(json.dumps({"task": task, "ok": False, "error": str(e)}))
            continue
        cold_s = time.perf_counter() - t0
        t1, c1 = time.perf_counter(), time.process_time()
        warm = instantiate(task, seed=args.seed)
        warm_cpu_s = time.process_time() - c1
        row = {"task": task, "ok": True, "scene": cold.scene, "cold_s": round(cold_s, 4),
               "scene_s": round(cold.timings["scene"], 4), "parse_s": round(cold.timings["parse"], 4),
               "warm_s": round(time.perf_counter() - t1, 4), "warm_cpu_s": round(warm_cpu_s, 4),
               "warm_instantiate_s": round(warm.timings["instantiate"], 4), "objects": len(warm.world.objects)}
        rows.append(row)
        print(json.dumps(row))
    summary: dict[str, object] = {"summary": args.set_, "tasks": len(rows)}
    for key in ("cold_s", "scene_s", "parse_s", "warm_s", "warm_cpu_s", "warm_instantiate_s"):
        values = [r[key] for r in rows]
        summary[key] = {"median": round(statistics.median(values), 4), "max": round(max(values), 4)}
    summary["cold_minus_scene_s"] = {"median": round(statistics.median(r["cold_s"] - r["scene_s"] for r in rows), 4),
                                     "max": round(max(r["cold_s"] - r["scene_s"] for r in rows), 4)}
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
