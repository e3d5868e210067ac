"""Spatial relations between objects derived from their 3D boxes: 'inside' and 'ontop'."""

from __future__ import annotations

import numpy as np
from numba import njit

INSIDE, ONTOP = 1, 2
"""Codes of the predicates in :func:`_supports`' output (0: neither)."""

_PREDICATES = {INSIDE: "inside", ONTOP: "ontop"}


def spatial_relations(
    mins: np.ndarray,
    maxs: np.ndarray,
    *,
    tol_m: float = 0.08,
    inside_fraction: float = 0.7,
    min_support_overlap: float = 0.5,
) -> list[tuple[int, str, int]]:
    """Relations (subject index, predicate, object index) among boxes (n, 3) min / max corners.

    A is inside B when at least ``inside_fraction`` of A's volume lies in B's box, A's top is
    below B's top and B is the larger box (the top test keeps a flat item resting on a table, whose
    voxelised box shares the table's top voxel, from reading as inside it); the smallest such
    container wins. Otherwise A is on top of B when A's bottom is within ``tol_m`` of B's top and
    at least ``min_support_overlap`` of A's footprint lies over B's; the highest such support wins.
    Ties go to the box listed first.
    """
    if len(mins) < 2:
        return []
    predicate, support = _supports(
        np.ascontiguousarray(mins, dtype=np.float64),
        np.ascontiguousarray(maxs, dtype=np.float64),
        tol_m,
        inside_fraction,
        min_support_overlap,
    )
    return [(a, _PREDICATES[p], int(support[a])) for a, p in enumerate(predicate.tolist()) if p]


@njit(cache=True)
def _supports(
    mins: np.ndarray, maxs: np.ndarray, tol_m: float, inside_fraction: float, min_support_overlap: float
) -> tuple[np.ndarray, np.ndarray]:
    """Per box A, its predicate code (``INSIDE``, ``ONTOP`` or 0) and the box it relates to, by the rules of
    :func:`spatial_relations`: one pass over the pairs, each box's best container and best support so far
    kept (a strictly better one replaces it, so ties go to the box listed first)."""
    n = mins.shape[0]
    size = np.maximum(maxs - mins, 1e-9)
    vol = size[:, 0] * size[:, 1] * size[:, 2]
    predicate = np.zeros(n, dtype=np.int8)
    support = np.full(n, -1, dtype=np.int64)
    for a in range(n):
        container, best_vol, base, best_top = -1, np.inf, -1, -np.inf
        for b in range(n):
            if b == a or not vol[a] < vol[b]:
                continue
            ox = max(min(maxs[a, 0], maxs[b, 0]) - max(mins[a, 0], mins[b, 0]), 0.0)
            oy = max(min(maxs[a, 1], maxs[b, 1]) - max(mins[a, 1], mins[b, 1]), 0.0)
            oz = max(min(maxs[a, 2], maxs[b, 2]) - max(mins[a, 2], mins[b, 2]), 0.0)
            if ox * oy * oz / vol[a] >= inside_fraction and maxs[a, 2] < maxs[b, 2] - 1e-6:
                if vol[b] < best_vol:
                    container, best_vol = b, vol[b]
            elif (
                ox * oy / (size[a, 0] * size[a, 1]) >= min_support_overlap
                and abs(mins[a, 2] - maxs[b, 2]) <= tol_m
                and maxs[b, 2] > best_top
            ):
                base, best_top = b, maxs[b, 2]
        if container >= 0:
            predicate[a], support[a] = INSIDE, container
        elif base >= 0:
            predicate[a], support[a] = ONTOP, base
    return predicate, support
