"""Frame rendering time per scene: one JSON object per scene on stdout.

Each line: scene, items (the scene's own small objects, unless ``--no-items``), number of drawn
boxes, scene area, frames timed, and the median / 90th percentile milliseconds of one 256x256
frame (depth + semantic + instance + RGB) on one core (and the median CPU ms), from robot poses
drawn at random among the free cells of the navigation grid. Scenes are generated with seed 0;
the numba kernels are compiled (or loaded from cache) before timing.

    python benchmarks/render.py [--scenes Rs_int Beechwood_0_int ...] [--frames 50] [--seed 0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from more_agent.errors import UserError  # noqa: E402
from more_agent.sim.clutter import add_distractors, clutter_rng  # noqa: E402
from more_agent.sim.navgrid import free_cells, nav_grid  # noqa: E402
from more_agent.sim.render import Renderer  # noqa: E402
from more_agent.sim.scenes import get_scene, scene_names  # noqa: E402
from more_agent.sim.world import World  # noqa: E402


def time_scene(
    name: str, frames: int, rng: np.random.Generator, renderer: Renderer, items: bool = True,
) -> dict[str, object]:
    """Median and 90th percentile frame time over ``frames`` random free poses in one scene (with its
    own small objects as items unless ``items`` is False)."""
    world = World.from_scene(get_scene(name, 0))
    n_items = len(add_distractors(world, clutter_rng(name, 0)).items) if items else 0
    grid = nav_grid(world)
    cells = free_cells(grid.free)
    picks = rng.integers(len(cells), size=frames)
    poses = [(*grid.centre(cells[k]), float(rng.uniform(-np.pi, np.pi))) for k in picks]
    geometry = renderer.geometry(world)
    times, cpu = [], []
    for x, y, yaw in poses:
        T = renderer.camera.pose(x, y, yaw)
        t0, c0 = time.perf_counter(), time.process_time()
        renderer.render_at(world, T)
        times.append((time.perf_counter() - t0) * 1000)
        cpu.append((time.process_time() - c0) * 1000)
    x0, y0, x1, y1 = world.scene.bounds
    return {
        "benchmark": "render_frame", "scene": name, "items": n_items, "boxes": geometry.n_boxes,
        "area_m2": round((x1 - x0) * (y1 - y0), 1),
        "frames": frames, "median_ms": round(float(np.median(times)), 3), "p90_ms": round(float(np.percentile(times, 90)), 3),
        "cpu_median_ms": round(float(np.median(cpu)), 3),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*", default=None, help="scene names (default: all 51)")
    parser.add_argument("--frames", type=int, default=50, help="frames timed per scene")
    parser.add_argument("--seed", type=int, default=0, help="seed of the pose sampling")
    parser.add_argument("--no-items", action="store_true", help="scenes without their own small objects")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    renderer = Renderer()
    warm = World.from_scene(get_scene("Rs_int", 0))
    renderer.render(warm)  # compile or load the kernels outside the timings
    for name in args.scenes or scene_names():
        try:
            row = time_scene(name, args.frames, rng, renderer, items=not args.no_items)
        except (RuntimeError, UserError) as e:  # a scene the generator cannot lay out: say so, go on
            print(f"{name}: {e}", file=sys.stderr)
            continue
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
