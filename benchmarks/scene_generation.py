"""Generation time of every BEHAVIOR-1K scene plan: one JSON object per scene, then a summary line.

Usage: python benchmarks/scene_generation.py [--seed N]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from more_agent.sim import catalog
from more_agent.sim.floorplan import generate_floorplan, scene_rng


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    catalog.taxonomy()
    catalog.category_synsets("fridge")
    warmup = time.perf_counter() - t0
    print(json.dumps({"measurement": "catalog_warmup", "seconds": round(warmup, 4)}))
    times = []
    for name in catalog.scene_names():
        t = time.perf_counter()
        s = generate_floorplan(name, catalog.scene_rooms(name), rng=scene_rng(name, args.seed), seed=args.seed)
        dt = time.perf_counter() - t
        times.append(dt)
        area = sum((r.bounds[2] - r.bounds[0]) * (r.bounds[3] - r.bounds[1]) for r in s.rooms)
        print(json.dumps({"measurement": "scene_generation", "scene": name, "seed": args.seed, "seconds": round(dt, 4),
                          "rooms": len(s.rooms), "doors": len(s.doors), "furniture": len(s.furniture),
                          "area_m2": round(area, 1)}))
    print(json.dumps({"measurement": "scene_generation_summary", "scenes": len(times),
                      "median_seconds": round(statistics.median(times), 4), "max_seconds": round(max(times), 4)}))


if __name__ == "__main__":
    main()
