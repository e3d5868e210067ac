"""Spatial relations between objects derived from their 3D boxes: 'inside' and 'ontop'."""

from __future__ import annotations

import numpy as np


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
    """
    n = len(mins)
    if n < 2:
        return []
    lo = np.maximum(mins[:, None, :], mins[None, :, :])
    hi = np.minimum(maxs[:, None, :], maxs[None, :, :])
    overlap = np.clip(hi - lo, 0, None)  # (A, B, 3)
    size = np.maximum(maxs - mins, 1e-9)
    vol = size.prod(1)
    inside = (
        (overlap.prod(2) / vol[:, None] >= inside_fraction)
        & (vol[:, None] < vol[None, :])
        & (maxs[:, None, 2] < maxs[None, :, 2] - 1e-6)
    )
    footprint = overlap[..., 0] * overlap[..., 1] / (size[:, 0] * size[:, 1])[:, None]
    touching = np.abs(mins[:, None, 2] - maxs[None, :, 2]) <= tol_m
    ontop = (footprint >= min_support_overlap) & touching & (vol[:, None] < vol[None, :])
    np.fill_diagonal(inside, False)
    np.fill_diagonal(ontop, False)
    out: list[tuple[int, str, int]] = []
    for a in range(n):
        if inside[a].any():  # the smallest container holds it
            cands = np.flatnonzero(inside[a])
            out.append((a, "inside", int(cands[np.argmin(vol[cands])])))
        elif ontop[a].any():
            cands = np.flatnonzero(ontop[a])
            out.append((a, "ontop", int(cands[np.argmax(maxs[cands, 2])])))
    return out
