"""Packing: where an item fits on or in a support, folded if it is cloth, stacked when the surface is full.

Pure geometry over :class:`~more_agent.sim.objects.WorldObject` boxes: the world
(:class:`~more_agent.sim.world.World`) hands in the support, the item and the objects that may stand
in the way, and rests the item where these functions say. Supports with inner shelf levels take items
``ontop`` on their highest level within the arm's reach.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from more_agent.robot_spec import ROBOT
from more_agent.sim.objects import WorldObject
from more_agent.vocabulary import Relation

SLAB_FRACTION = 0.08
"""Thickness of a container's bottom / top slab as a share of its height (inner items rest on it)."""

SLOT_GAP_M = 0.02
"""Gap left between neighbouring items on one support."""

REACH_TOP_M = ROBOT.reach_top_m
"""Highest surface the arm places on (``RobotSpec.reach_top_m``: the Fetch arm with its torso lowered, like
the 1.2 m camera, which sees items there from about a metre away). A support with inner levels whose top
is higher takes items on top on its highest level at most this high (``support_surface``)."""

LEVELLED_CATEGORIES = frozenset(
    """shelf bookcase grocery_shelf commercial_kitchen_shelf candy_dispenser_shelf dry_food_dispenser_shelf
    shoe_rack magazine_rack snack_rack""".split()
)
"""Supports with inner shelf levels: BEHAVIOR-1K's ``ontop`` holds on any of their levels."""

LEVEL_STEP_M = 0.4
"""Spacing of the inner levels of a ``LEVELLED_CATEGORIES`` support, from its bottom slab up."""

MAX_FOLDS = 3
"""Times a cloth item is folded in half, at most, to fit where it is put (``fit``)."""

CLOTH_LAYER_M = 0.01
"""Thickness of one layer of cloth: a garment folded n times lies 2^n layers thick (``fit``)."""


def support_surface(support: WorldObject, relation: Relation) -> tuple[np.ndarray, np.ndarray, float]:
    """(footprint min xy, footprint max xy, surface z) where items rest in / on ``support``."""
    lo, hi = support.box()
    if relation == "ontop":
        return lo[:2], hi[:2], top_level(support)
    slab = SLAB_FRACTION * support.size[2]
    margin = np.minimum(0.05, support.size[:2] * 0.1)
    return lo[:2] + margin, hi[:2] - margin, support.bottom + slab


def magic_fit(
    obj: WorldObject,
    support: WorldObject,
    relation: Relation,
    others: Sequence[WorldObject],
) -> tuple[np.ndarray, np.ndarray]:
    """Centre and size where ``obj`` fits, stacking when the surface is full (``fit``), else the
    support's centre: magic placement, like the paper's, never fails for lack of room."""
    fitted = fit(obj, support, relation, others, stack=True)
    if fitted is not None:
        return fitted
    lo, hi, z = support_surface(support, relation)
    cx, cy = (lo + hi) / 2
    return np.array([cx, cy, z + obj.size[2] / 2]), obj.size


def fit(
    obj: WorldObject,
    support: WorldObject,
    relation: Relation,
    others: Sequence[WorldObject],
    *,
    stack: bool = False,
    rng: np.random.Generator | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, size) of ``obj`` at a free slot (``free_slot``; ``rng`` draws it) among ``others`` in its own shape
    or, for cloth, folded in half up to ``MAX_FOLDS`` times, as a garment goes into a washer or a carton;
    None when no shape fits. A fold halves the longer side and lays the garment flat, 2^folds
    layers of cloth thick at most (a garment model's box is a draped heap, mostly air)."""
    lo, hi, _ = support_surface(support, relation)
    size, folds = obj.size, MAX_FOLDS if obj.cloth else 0
    for fold in range(folds + 1):
        if fold:
            size = size * np.where(np.arange(3) == np.argmax(size[:2]), 0.5, 1.0)
            size[2] = min(size[2], CLOTH_LAYER_M * 2**fold)
        if fold < folds and np.any(size[:2] + SLOT_GAP_M > hi - lo):
            continue  # cloth folds rather than overhang
        slot = free_slot(obj, support, relation, others, stack=stack, size=size, rng=rng)
        if slot is not None:
            return slot, size
    return None


def free_slot(
    obj: WorldObject,
    support: WorldObject,
    relation: Relation,
    others: Sequence[WorldObject],
    *,
    stack: bool = False,
    size: np.ndarray | None = None,
    rng: np.random.Generator | None = None,
) -> np.ndarray | None:
    """Centre of a slot on the support where the item's box (of ``size``, default its own) meets none of
    ``others`` standing in the space it would take (``in_space``): the first in reading order, or, on top
    of a support, one ``rng`` draws among the free ones, as OmniGibson samples a pose over a support at
    random. Inside a container the first still: the paper's robot sees all that is inside once it is
    opened, wherever it lies, and packed densely a container holds what bddl puts in it (random slots
    left no room for make_baked_pears' wine bottle in its cabinet); with
    ``stack``, when the surface is full, at a slot flush with its far edges (``_slots``), else on the
    next layer up (on the highest item in the way, whichever support it rests on; in a closed-lid
    container only while it fits under the lid). An item wider than the surface overhangs it, centred.
    None when there is no such slot."""
    size = obj.size if size is None else size
    lo, hi, z = support_surface(support, relation)
    half = size[:2] / 2 + SLOT_GAP_M / 2
    slots = _slots(lo, hi, half, flush=stack)
    # where the item may stand: the surface, and beyond it where an item wider than it overhangs
    span_lo, span_hi = np.minimum(lo, slots.min(axis=0) - half), np.maximum(hi, slots.max(axis=0) + half)
    while True:
        there = in_space(others, span_lo, span_hi, z, size[2])
        free = slots
        if there:
            centers = np.array([o.center[:2] for o in there])
            reach = half + np.array([o.size[:2] / 2 for o in there])
            # per axis, (objects, slots): a slot is taken when it lies within reach of an object along both
            near_x = np.abs(slots[:, 0] - centers[:, :1]) < reach[:, :1]
            near_y = np.abs(slots[:, 1] - centers[:, 1:]) < reach[:, 1:]
            free = slots[~(near_x & near_y).any(axis=0)]
        if len(free):
            x, y = free[0 if rng is None or relation == "inside" else int(rng.integers(len(free)))]
            return np.array([x, y, z + size[2] / 2])
        layer = [o.top for o in there if o.kind == "item"]
        lidded = relation == "inside" and support.openable
        if not stack or not layer or (lidded and max(layer) + size[2] > support.top):
            return None
        z = max(layer)


def in_space(objs: Sequence[WorldObject], lo: np.ndarray, hi: np.ndarray, z: float, height: float) -> list[WorldObject]:
    """The objects of ``objs`` in the space an item of ``height`` would take on the surface (``lo``,
    ``hi``, ``z``)."""
    if not objs:
        return []
    lo3, hi3 = np.array([lo[0], lo[1], z]), np.array([hi[0], hi[1], z + height])
    centers = np.concatenate([o.center for o in objs]).reshape(-1, 3)
    halves = np.concatenate([o.size for o in objs]).reshape(-1, 3) / 2
    eps = 1e-5  # boxes that merely touch (a card under a barrel's band) do not overlap
    # the three axes joined one by one, not np.all over an axis of 3 (cheaper: docs/benchmarks.md, distractor placement)
    meets = (centers - halves < hi3 - eps) & (centers + halves > lo3 + eps)
    return [objs[i] for i in np.flatnonzero(meets[:, 0] & meets[:, 1] & meets[:, 2]).tolist()]


def _slots(lo: np.ndarray, hi: np.ndarray, half: np.ndarray, *, flush: bool) -> np.ndarray:
    """(n, 2) slot centres on a surface from ``lo`` to ``hi`` for an item of half extents ``half``: a
    grid from the near corner in reading order (rows follow y); with ``flush``, then the same grid
    mirrored to each other corner, whose slots lie flush with the far edges where the first grid
    leaves a strip narrower than the item (a lamp in one corner of a nightstand leaves the far end).
    Read-only: a world's distractors ask for the same grids again and again (one size per category)."""
    return _slot_grid(*(np.asarray(a, dtype=float).tobytes() for a in (lo, hi, half)), flush)


@lru_cache(maxsize=4096)
def _slot_grid(lo_bytes: bytes, hi_bytes: bytes, half_bytes: bytes, flush: bool) -> np.ndarray:
    """``_slots`` of the float64 arrays these bytes hold."""
    lo, hi, half = (np.frombuffer(b) for b in (lo_bytes, hi_bytes, half_bytes))
    xs, ys = (_slot_centres(lo[k], hi[k], half[k]) for k in (0, 1))
    grids = [(xs, ys)]
    if flush:
        fx, fy = lo[0] + hi[0] - xs[::-1], lo[1] + hi[1] - ys[::-1]
        grids += [(fx, ys), (xs, fy), (fx, fy)]
    out = []
    for gx, gy in (np.meshgrid(a, b) for a, b in grids):
        out.append(np.stack([gx.ravel(), gy.ravel()], axis=1))
    slots = np.concatenate(out)
    slots.setflags(write=False)
    return slots


def _slot_centres(lo: float, hi: float, half: float) -> np.ndarray:
    """Slot centres along one axis of a surface from ``lo`` to ``hi`` for an item of half-width ``half``;
    the surface's centre alone when the item is wider."""
    centres = np.arange(lo + half, hi - half + 1e-9, 2 * half)
    return centres if len(centres) else np.array([(lo + hi) / 2])


def top_level(support: WorldObject) -> float:
    """Height items rest at on top of ``support``: its top, or for a levelled support taller than the
    arm reaches (``LEVELLED_CATEGORIES``) its highest inner level at most ``REACH_TOP_M`` high. Inner
    levels lie ``LEVEL_STEP_M`` apart from the bottom slab up, a step or more below the top; a
    support with none within reach (a single board hung high) keeps its top."""
    if support.category not in LEVELLED_CATEGORIES or support.top <= REACH_TOP_M:
        return support.top
    first = support.bottom + SLAB_FRACTION * support.size[2]
    highest = min(REACH_TOP_M, support.top - LEVEL_STEP_M)
    if highest < first:
        return support.top
    return first + LEVEL_STEP_M * np.floor((highest - first) / LEVEL_STEP_M)
