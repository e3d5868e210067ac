"""Mapping benchmark on the shared synthetic apartments (../shared/benchmarks/synth_apartment.py)
and on BEHAVIOR-1K scenes from rendered frames.

    python benchmarks/mapping.py --size 600      # one JSON object per size on stdout
    python benchmarks/mapping.py --size all      # 200, 400, 600, 1200, 2000
    python benchmarks/mapping.py --scene house_single_floor Wainscott_0_garden

Per size: median seconds per graph stage over 5 builds (Voronoi, sparsification, regions, object
assignment, frontiers), their total, peak traced MB of the graph build, node / edge counts before
and after sparsification, region count, share of objects assigned to their true room, and the
median per-frame cost of fusing a 256x256 frame into the voxel grid + BEV.
Per scene (with the scene's own small objects unless ``--no-items``): the robot turns once in place
at viewpoints about 4 m apart over every room (doors open), through the real renderer and
scene-graph builder; median seconds per frame fusion, wall and CPU seconds and peak traced MB of
the whole graph build, its size, and regions against rooms. CPU seconds are the figure to read on
a shared machine.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / ".." / "shared" / "benchmarks"))
from synth_apartment import make_apartment  # noqa: E402

from more_agent.mapping import OCCUPIED, Grid, MappingConfig, VoxelMap, assign_objects, region_graph  # noqa: E402

SIZES = (200, 400, 600, 1200, 2000)
CFG = MappingConfig()
RES = CFG.resolution_m
GRID = Grid(resolution_m=RES)


def _door_points(occ: np.ndarray, door: tuple[int, int], width: int = 12, wall: int = 2) -> np.ndarray:
    """Points covering a door's opening, oriented along the wall it sits in."""
    r, c = door
    along_cols = occ[r, max(c - width, 0)] == OCCUPIED or occ[r, min(c + width, occ.shape[1] - 1)] == OCCUPIED
    t = np.linspace(-width / 2, width / 2, 13)
    n = np.linspace(-wall / 2, wall / 2, 3)
    a, b = np.meshgrid(t, n)
    cells = np.stack([r + b.ravel(), c + a.ravel()], 1) if along_cols else np.stack([r + a.ravel(), c + b.ravel()], 1)
    return GRID.xy_of(cells)


def build_graph(occ, doors, objects, rooms) -> tuple[dict, dict]:
    """The whole graph pipeline (``region_graph``) on one map; returns (seconds per stage, counts)."""
    obj_xy = GRID.xy_of(np.array([(o[0], o[1]) for o in objects]))
    room_centres = np.array([((a0 + a1) / 2, (b0 + b1) / 2) for a0, a1, b0, b1 in rooms]) * RES
    vp = room_centres[[o[2] for o in objects]]
    out = region_graph(occ, GRID, door_points=[_door_points(occ, d) for d in doors], objects_xy=obj_xy,
                       viewpoints_xy=vp, blocked=occ == OCCUPIED, config=CFG)
    truth = assign_objects(out.graph, out.labels, vp, vp, cut=out.cut)
    counts = {
        "nodes_dense": out.dense.n_nodes, "edges_dense": out.dense.n_edges,
        "nodes_sparse": out.graph.n_nodes, "edges_sparse": out.graph.n_edges,
        "regions": int(out.labels.max()) + 1, "rooms": len(rooms),
        "assignment_accuracy": float(np.mean(out.assigned == truth)),
    }
    return out.timings_s, counts


def frame_update_s(n_frames: int = 30) -> float:
    """Median seconds to fuse one 256x256 frame (floor + wall) into the voxel grid and BEV."""
    h = w = 256
    K = np.array([[128.0, 0, 128], [0, 128.0, 128], [0, 0, 1]])
    vmap = VoxelMap(free_class_ids=[1], resolution_m=RES, max_range_m=CFG.max_range_m)
    v, u = np.mgrid[0:h, 0:w]
    ray = np.stack([(u + 0.5 - 128) / 128, (v + 0.5 - 128) / 128, np.ones((h, w))], -1)
    times = []
    for i in range(n_frames + 2):
        yaw = 0.2 * i
        tilt = np.deg2rad(20)
        fwd = np.array([np.cos(yaw) * np.cos(tilt), np.sin(yaw) * np.cos(tilt), -np.sin(tilt)])
        right = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
        down = np.cross(fwd, right)
        T = np.eye(4)
        T[:3, :3] = np.stack([right, down, fwd], 1)
        T[:3, 3] = [0.05 * i, 0.0, 1.2]
        dirs = ray @ T[:3, :3].T
        t_floor = np.where(dirs[..., 2] < 0, -1.2 / np.minimum(dirs[..., 2], -1e-9), np.inf)
        t_wall = np.where(dirs[..., 0] > 0, (3.0 - T[0, 3]) / np.maximum(dirs[..., 0], 1e-9), np.inf)
        depth = np.minimum(t_floor, t_wall)
        sem = np.where(t_wall < t_floor, 5, 1).astype(np.int32)
        depth = np.where(depth * np.linalg.norm(ray, axis=-1) <= CFG.max_range_m, depth, np.nan).astype(np.float32)
        t0 = time.perf_counter()
        vmap.integrate(depth, sem, np.zeros((h, w), np.int32), K, T)
        if i >= 2:  # first calls compile / load the numba cache and allocate the grid
            times.append(time.perf_counter() - t0)
    return float(np.median(times))


def run(size: int) -> dict:
    occ, doors, objects, rooms = make_apartment(N=size, res=RES)
    occ = occ.astype(np.int8)
    build_graph(occ, doors, objects, rooms)  # warm-up: numba compilation / cache load
    runs = []
    for _ in range(5):
        stages, counts = build_graph(occ, doors, objects, rooms)
        runs.append({**stages, "total_s": sum(stages.values())})
    best = {k: float(np.median([r[k] for r in runs])) for k in runs[0]}
    tracemalloc.start()
    build_graph(occ, doors, objects, rooms)
    peak_mb = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return {"size": size, "free_cells": int((occ == 1).sum()), **{k: round(v, 4) for k, v in best.items()},
            "peak_mb": round(peak_mb, 1), **counts, "frame_update_s": round(frame_update_s(), 5)}


VIEWPOINT_SPACING_M = 4.0
"""Distance between the viewpoints the scene benchmark turns at (several in a large room)."""


def run_scene(name: str, items: bool = True) -> dict:
    """Explore a BEHAVIOR-1K scene room by room from rendered frames; time fusion and the graph build.

    With ``items`` the world holds the scene's own small objects (``sim.clutter``), as episodes do.
    """
    from collections import Counter

    from more_agent.planners.policies import Embodiment
    from more_agent.sim.clutter import add_distractors, clutter_rng
    from more_agent.sim.env import SimRobot
    from more_agent.sim.navgrid import nav_grid
    from more_agent.sim.scenes import get_scene
    from more_agent.sim.world import World

    world = World.from_scene(get_scene(name, 0))
    n_items = len(add_distractors(world, clutter_rng(name, 0)).items) if items else 0
    for door in world.scene.doors:
        world.set_open(door.id, True)
    grid = nav_grid(world)
    body = Embodiment(SimRobot(world))
    fuse_times: list[float] = []
    integrate = body.builder.integrate

    def timed(*args: object, **kwargs: object) -> None:
        t0 = time.perf_counter()
        integrate(*args, **kwargs)
        fuse_times.append(time.perf_counter() - t0)

    body.builder.integrate = timed  # type: ignore[method-assign]
    for room in world.scene.rooms:  # a full turn at viewpoints VIEWPOINT_SPACING_M apart over every room
        x0, y0, x1, y1 = room.bounds
        nx, ny = (max(1, round((x1 - x0) / VIEWPOINT_SPACING_M)), max(1, round((y1 - y0) / VIEWPOINT_SPACING_M)))
        for i in range(nx):
            for j in range(ny):
                x, y = x0 + (i + 0.5) * (x1 - x0) / nx, y0 + (j + 0.5) * (y1 - y0) / ny
                world.set_robot_pose(*grid.centre(grid.snap(x, y)), 0.0)
                body.look_around()
    body.build()  # warm-up
    builds, cpu = [], []
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        graph = body.build()
        builds.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    tracemalloc.start()
    body.build()
    peak_mb = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    region_rooms = [Counter(world.room_at(*graph.nav.node_xy[i]) for i in r.nav_nodes).most_common(1)[0][0]
                    for r in graph.regions.values() if r.nav_nodes]
    occ = graph.occupancy
    return {"scene": name, "rooms": len(world.scene.rooms), "items": n_items, "frames": len(fuse_times),
            "known_cells": int((occ.grid != 0).sum()) if occ is not None else 0,
            "frame_fuse_s_median": round(float(np.median(fuse_times[2:])), 5),
            "graph_build_s_median": round(float(np.median(builds)), 4),
            "graph_build_cpu_s_median": round(float(np.median(cpu)), 4), "graph_build_peak_mb": round(peak_mb, 1),
            "nav_nodes_sparse": len(graph.nav.node_xy), "regions": len(graph.regions),
            "rooms_covered_by_regions": len(set(region_rooms)), "objects": len(graph.objects)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="600", help="cells per side, or 'all'")
    parser.add_argument("--scene", nargs="*", default=None, help="BEHAVIOR-1K scenes from rendered frames instead")
    parser.add_argument("--no-items", action="store_true", help="scenes without their own small objects")
    args = parser.parse_args()
    if args.scene:
        for name in args.scene:
            print(json.dumps(run_scene(name, items=not args.no_items)), flush=True)
        return
    for size in SIZES if args.size == "all" else (int(args.size),):
        print(json.dumps(run(size)), flush=True)


if __name__ == "__main__":
    main()
