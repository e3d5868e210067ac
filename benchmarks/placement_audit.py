"""Placement audit: task items that no camera pose could see or no arm could reach, over a task set.

``python benchmarks/placement_audit.py [--set more-paper] [--seeds 3]``

Instantiates every task x seed in two worlds: the one the pipeline-ceiling issue was filed on
(``start="task-room"``, no distractors) and the default one (random start, the scene's own small
objects). Per world with a defect it prints one JSON line naming the items
(``sim.placement_audit``: ``enclosed`` in another object's box, with that object, and
``out_of_reach`` above ``REACH_TOP_M``); then one summary line per world kind: worlds, task items,
defects (enclosed by furniture or by another item), and the distractors enclosed.
"""

from __future__ import annotations

import argparse
import json

from more_agent.errors import UserError
from more_agent.sim.instantiate import instantiate
from more_agent.sim.placement_audit import audit
from more_agent.sim.tasks import task_set

WORLDS = {"task-room, no distractors": {"start": "task-room", "distractors": False}, "default": {}}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--set", default="more-paper", dest="set_")
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args()
    for kind, options in WORLDS.items():
        totals = {"worlds": 0, "failed": 0, "items": 0, "enclosed_by_furniture": 0, "enclosed_by_item": 0,
                  "out_of_reach": 0, "distractors_enclosed": 0}
        for task in task_set(args.set_):
            for seed in range(args.seeds):
                try:
                    inst = instantiate(task, seed=seed, **options)
                except UserError:
                    totals["failed"] += 1
                    continue
                virtual = set(inst.virtual_scopes)
                items = sorted({n for s, n in inst.scope.items() if s not in virtual and inst.world.objects.get(n) is not None
                                and inst.world.objects[n].kind == "item"})
                found = audit(inst.world, items)
                totals["worlds"] += 1
                totals["items"] += len(items)
                for encloser in found["enclosed"].values():
                    totals["enclosed_by_item" if encloser.startswith("item") else "enclosed_by_furniture"] += 1
                totals["out_of_reach"] += len(found["out_of_reach"])
                totals["distractors_enclosed"] += len(audit(inst.world, inst.distractors)["enclosed"])
                if found["enclosed"] or found["out_of_reach"]:
                    print(json.dumps({"world": kind, "task": task, "seed": seed, "scene": inst.scene, **found}), flush=True)
        print(json.dumps({"summary": kind, "set": args.set_, "seeds": args.seeds, **totals}), flush=True)


if __name__ == "__main__":
    main()
