"""Benchmark: do maps and scene graphs stay the same when frames on the way are fused at a coarser cadence?

Each episode runs at the reference cadence (``--reference``, default 0.3 m or any turn: the cadence
before the sensing schedule, a frame every four 7.5 cm moves and after every turn sequence). A shadow
scene-graph builder receives the same frames the candidate cadence (``--candidate``) would fuse along
the very same path (every frame where the robot stops; on the way only those the candidate schedule
finds due), so the two maps differ only by the frames left out, not by the decisions they led to.
At the end of the episode both graphs are built from the robot's final pose and compared:

- ``cells_agree``: BEV cells with the same state (unknown, free, occupied) over the cells known in either;
- ``occupied_kept``: the reference's occupied cells also occupied in the candidate's map;
- ``objects_found``: objects of the reference graph also in the candidate's (by instance), and the reverse;
- ``instances_seen``: instances seen at all (the rTP count) by the candidate over the reference;
- ``regions``: region counts of both graphs.

One JSON line per episode, then a summary line (min and mean over episodes)::

    python benchmarks/sensing_cadence.py --tasks more-paper --seed 0 [--limit N] [--candidate 0.6 30]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from more_agent.eval.episode import run_episode  # noqa: E402
from more_agent.eval.harness import resolve_tasks  # noqa: E402
from more_agent.planners.policies.embodiment import Embodiment  # noqa: E402
from more_agent.planners.policies.sensing import SensingSchedule  # noqa: E402
from more_agent.records import EpisodeSpec  # noqa: E402
from more_agent.scene_graph import SceneGraph, SceneGraphBuilder  # noqa: E402
from more_agent.sensing_spec import SensingCadence  # noqa: E402

REFERENCE = SensingCadence(distance_m=0.3, angle_deg=1e-3)
"""A frame every 0.3 m (four full moves) and after every turn: the cadence before the schedule."""


class Shadowed:
    """Installs, on every :class:`Embodiment` built while active, the reference schedule and a shadow
    builder fed the candidate's frames; keeps the embodiments for the comparison."""

    def __init__(self, reference: SensingCadence, candidate: SensingCadence) -> None:
        self.reference, self.candidate = reference, candidate
        self.bodies: list[Embodiment] = []

    def __enter__(self) -> Shadowed:
        self._init, self._due = Embodiment.__init__, Embodiment.sense_if_due
        shadowed = self

        def init(body: Embodiment, *args: Any, **kwargs: Any) -> None:
            shadowed._init(body, *args, **kwargs)
            shadowed._attach(body)

        def sense_if_due(body: Any) -> None:
            pose = body.robot.pose
            if body.schedule.due(*pose):
                body.shadow_take = body.shadow_schedule.due(*pose)
                body.sense()
                body.shadow_take = True

        Embodiment.__init__ = init  # type: ignore[method-assign]
        Embodiment.sense_if_due = sense_if_due  # type: ignore[method-assign]
        return self

    def __exit__(self, *exc: object) -> None:
        Embodiment.__init__ = self._init  # type: ignore[method-assign]
        Embodiment.sense_if_due = self._due  # type: ignore[method-assign]

    def _attach(self, body: Any) -> None:
        body.schedule = SensingSchedule(self.reference)
        body.shadow_schedule = SensingSchedule(self.candidate)
        body.shadow = SceneGraphBuilder(body.robot.class_names, body.builder.config)
        body.shadow_take, body.shadow_frames, body.frames = True, 0, 0
        integrate, remember = body.builder.integrate, body.builder.remember

        def both_integrate(*args: Any) -> None:
            integrate(*args)
            body.frames += 1
            if body.shadow_take:
                body.shadow.integrate(*args)
                body.shadow_frames += 1
                body.shadow_schedule.fused(*body.robot.pose)

        def both_remember(*args: Any) -> None:
            remember(*args)
            body.shadow.remember(*args)

        body.builder.integrate, body.builder.remember = both_integrate, both_remember
        self.bodies.append(body)


def compare(reference: SceneGraph, candidate: SceneGraph) -> dict[str, float]:
    """Agreement of two graphs' BEV maps and objects (see the module docstring)."""
    a, b = _aligned(reference, candidate)
    known = (a > 0) | (b > 0)
    ref_objects = {o.instance_id for o in reference.objects.values()}
    cand_objects = {o.instance_id for o in candidate.objects.values()}
    return {
        "cells_agree": round(float((a == b)[known].mean()), 4),
        "occupied_kept": round(float((b[a == 2] == 2).mean()), 4),
        "objects_found": round(len(ref_objects & cand_objects) / max(len(ref_objects), 1), 4),
        "objects_extra": len(cand_objects - ref_objects),
        "regions": [len(reference.regions), len(candidate.regions)],
    }


def _aligned(reference: SceneGraph, candidate: SceneGraph) -> tuple[np.ndarray, np.ndarray]:
    """Both occupancy grids on one common extent (cells outside a map count as unknown)."""
    ra, rb = reference.occupancy, candidate.occupancy
    assert ra is not None and rb is not None and ra.resolution_m == rb.resolution_m
    res = ra.resolution_m
    oa, ob = np.asarray(ra.origin_xy), np.asarray(rb.origin_xy)
    origin = np.minimum(oa, ob)
    shift_a, shift_b = np.rint((oa - origin) / res).astype(int), np.rint((ob - origin) / res).astype(int)
    shape = np.maximum(shift_a + ra.grid.shape, shift_b + rb.grid.shape)
    out = []
    for grid, shift in ((ra.grid, shift_a), (rb.grid, shift_b)):
        full = np.zeros(shape, dtype=np.int8)
        full[shift[0] : shift[0] + grid.shape[0], shift[1] : shift[1] + grid.shape[1]] = grid
        out.append(full)
    return out[0], out[1]


def measure(spec: EpisodeSpec, reference: SensingCadence, candidate: SensingCadence) -> dict[str, object]:
    """One episode at the reference cadence with the candidate's shadow map; their agreement at its end."""
    with Shadowed(reference, candidate) as shadowed, tempfile.TemporaryDirectory() as d:
        record = run_episode(spec, out_dir=Path(d))
    body: Any = shadowed.bodies[-1]
    ref_graph, cand_graph = body.builder.build(body.xy, body.trajectory), body.shadow.build(body.xy, body.trajectory)
    seen_ref = set(body.builder._viewpoints)
    seen_cand = set(body.shadow._viewpoints)
    return {
        "task": spec.task,
        "seed": spec.seed,
        "planner": spec.planner,
        "success": record.success,
        "frames": [body.frames, body.shadow_frames],
        **compare(ref_graph, cand_graph),
        "instances_seen": round(len(seen_cand & seen_ref) / max(len(seen_ref), 1), 4),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tasks", default="more-paper")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--limit", type=int, default=None)
    p.add_argument("--planner", default="grounded")
    p.add_argument(
        "--candidate",
        nargs=2,
        type=float,
        default=None,
        metavar=("METRES", "DEGREES"),
        help="default: the schedule's default cadence",
    )
    a = p.parse_args()
    candidate = SensingCadence(distance_m=a.candidate[0], angle_deg=a.candidate[1]) if a.candidate else SensingCadence()
    rows = []
    for task in resolve_tasks(a.tasks)[: a.limit]:
        row = measure(EpisodeSpec(task=task, seed=a.seed, planner=a.planner), REFERENCE, candidate)
        rows.append(row)
        print(json.dumps(row), flush=True)
    keys = ("cells_agree", "occupied_kept", "objects_found", "instances_seen")
    print(
        json.dumps(
            {
                "candidate": candidate.model_dump(),
                "episodes": len(rows),
                "frames": [sum(r["frames"][0] for r in rows), sum(r["frames"][1] for r in rows)],  # type: ignore[index]
                **{
                    k: {"min": min(r[k] for r in rows), "mean": round(statistics.mean(r[k] for r in rows), 4)}  # type: ignore[type-var]
                    for k in keys
                },
            }
        ),
        flush=True,
    )


if __name__ == "__main__":
    main()
