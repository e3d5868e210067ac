"""Regenerate ``more_agent/data/task_data.json``: ``python scripts/build_task_data.py [--out PATH | --check]``.

For every bddl activity: the suitable scenes (``tasks.compute_suitable_scenes``), object and goal
literal counts, whether the goal is pure rearrangement, whether it instantiates in its first
suitable scene with seed 0 (else why not) and whether any state meets its goal there
(``GoalChecker.satisfiable``). The behavior-rearrange set is derived from these: instantiable,
satisfiable rearrangement goals.
Takes a few minutes, most of it generating the 51 scene plans once. It prints how many of the
1016 activities instantiate (the figure docs/tasks.md reports) and which activities instantiate
now but not in the package data (``gained``) or the other way round (``lost``), and the activities whose
goal no state meets (``unsatisfiable``); ``--check`` only
prints, writing nothing.
"""

from __future__ import annotations

import argparse
import json
import sys
from importlib import resources
from pathlib import Path
from typing import Any

from more_agent.errors import UserError
from more_agent.sim.tasks import (
    compute_suitable_scenes,
    is_rearrangement_goal,
    load_task,
    paper_tasks,
    task_names,
)

TASK_DATA_VERSION = 1


def build_task_data(names: list[str] | None = None, progress: bool = False) -> dict[str, Any]:
    """The task data document for ``names`` (default: every activity)."""
    from more_agent.sim.goals import GoalChecker
    from more_agent.sim.instantiate import instantiate_in_scene
    from more_agent.sim.scenes import get_scene

    tasks: dict[str, Any] = {}
    for i, name in enumerate(names or task_names()):
        d = load_task(name)
        scenes = compute_suitable_scenes(d)
        entry: dict[str, Any] = {
            "scenes": scenes,
            "n_objects": len(d.scopes),
            "n_goal_literals": d.n_goal_literals,
            "rearrangement_goal": is_rearrangement_goal(d),
            "goal_predicates": sorted(d.goal_predicates),
            "instantiable": False,
            "satisfiable": None,
            "reason": "no suitable scene" if not scenes else "",
            "unsupported_init": [],
        }
        if scenes:
            try:
                scene = get_scene(scenes[0], 0)
            except RuntimeError as e:  # the floor-plan generator gave up on this scene
                entry["reason"] = f"scene {scenes[0]} could not be generated: {e}"
                scene = None
            try:
                if scene is not None:
                    inst = instantiate_in_scene(d, scene, 0)
                    goals = GoalChecker(inst)  # a task counts only when its goal can be scored too
                    entry["instantiable"] = True
                    entry["satisfiable"] = goals.satisfiable
                    entry["unsupported_init"] = inst.unsupported_literals
            except UserError as e:
                entry["reason"] = str(e)
        tasks[name] = entry
        if progress and i % 50 == 0:
            print(f"{i} {name}", file=sys.stderr)
    rearrange = sorted(n for n, e in tasks.items() if e["rearrangement_goal"] and e["instantiable"] and e["satisfiable"])
    return {
        "version": TASK_DATA_VERSION,
        "how": "scenes: bddl knowledge-base matching of inroom requirements on combined_room_object_list.json; "
        "instantiable: more_agent.sim.instantiate in the first suitable scene, seed 0, and its goal has "
        "a bddl ground option; satisfiable: some state meets the goal (more_agent.sim.satisfiable)",
        "sets": {"more-paper": sorted(paper_tasks()), "behavior-rearrange": rearrange},
        "tasks": tasks,
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = Path(str(resources.files("more_agent").joinpath("data", "task_data.json")))
    parser.add_argument("--out", type=Path, default=default, help="output JSON path")
    parser.add_argument("--check", action="store_true", help="print the figures and changes only, write nothing")
    args = parser.parse_args(argv)
    before = json.loads(default.read_text())["tasks"]
    data = build_task_data(progress=True)
    if not args.check:
        args.out.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    now = {n for n, e in data["tasks"].items() if e["instantiable"]}
    was = {n for n, e in before.items() if e["instantiable"]}
    unsatisfiable = sorted(n for n, e in data["tasks"].items() if e["satisfiable"] is False)
    print(json.dumps({"tasks": len(data["tasks"]), "instantiable": len(now), "unsatisfiable": unsatisfiable,
                      "behavior-rearrange": len(data["sets"]["behavior-rearrange"]),
                      "package_data_instantiable": len(was), "gained": sorted(now - was), "lost": sorted(was - now),
                      "out": None if args.check else str(args.out)}))


if __name__ == "__main__":
    main()
