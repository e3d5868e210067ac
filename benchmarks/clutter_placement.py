"""Where the scenes' own objects end up: one JSON line per scene, then one per scene type.

``python benchmarks/clutter_placement.py [--scenes office_large ...] [--seeds 3]``

For each BEHAVIOR-1K scene and seed, the scene's plan gets its distractors (``sim.clutter``, as at
instantiation, without a task) and every item is counted by where it rests: on top of furniture,
inside a closed container (unseen until opened), inside an open one, or on the floor. Each line
gives the items per seed, the shares, and (per scene) the furniture categories holding the most
items. No planner runs; scene types are those of ``world_stats.py``.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter, defaultdict

from world_stats import scene_type

from more_agent.sim.clutter import add_distractors, clutter_rng
from more_agent.sim.scenes import get_scene, scene_names
from more_agent.sim.world import World


def placements(scene: str, seed: int) -> tuple[Counter[str], Counter[str]]:
    """(where -> items, 'support relation' -> items) of one scene's distractors for a seed."""
    world = World.from_scene(get_scene(scene, seed))
    where: Counter[str] = Counter()
    supports: Counter[str] = Counter()
    for name in add_distractors(world, clutter_rng(scene, seed)).items:
        item = world.get(name)
        parent = world.get(item.parent) if item.parent else None
        if parent is None or parent.kind == "floor":
            where["floor"] += 1
            continue
        if item.relation == "inside":
            where["inside_closed" if world.enclosing_closed_container(name) else "inside_open"] += 1
        else:
            where["ontop"] += 1
        supports[f"{parent.category} {item.relation}"] += 1
    return where, supports


def _shares(where: Counter[str]) -> dict[str, float]:
    total = sum(where.values())
    return {k: round(v / total, 3) for k, v in sorted(where.items())} if total else {}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=scene_names())
    parser.add_argument("--seeds", type=int, default=3, help="seeds 0 .. N-1 per scene")
    args = parser.parse_args()
    by_type: dict[str, Counter[str]] = defaultdict(Counter)
    for scene in args.scenes:
        where: Counter[str] = Counter()
        supports: Counter[str] = Counter()
        for seed in range(args.seeds):
            w, s = placements(scene, seed)
            where += w
            supports += s
        by_type[scene_type(scene)] += where
        print(json.dumps({"scene": scene, "items_per_seed": round(sum(where.values()) / args.seeds, 1),
                          "share": _shares(where), "top_supports": supports.most_common(6)}), flush=True)
    for kind, where in sorted(by_type.items()):
        print(json.dumps({"scene_type": kind, "items": sum(where.values()), "share": _shares(where)}))


if __name__ == "__main__":
    main()
