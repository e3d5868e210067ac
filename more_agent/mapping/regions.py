"""Region separation at doors: one oriented Gaussian kernel per observed door, edges whose line
integral through the kernels exceeds a threshold are cut, regions are the remaining connected
components; components that share one door-free patch of free space are merged (paper S.5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from more_agent.mapping.graph import NavGraph
from more_agent.mapping.occupancy import FREE
from more_agent.sim.grid import Grid


@dataclass(frozen=True)
class DoorKernel:
    """Oriented 2D Gaussian over a door: ``center_xy`` (m), ``angle_rad`` of the door's width
    axis, standard deviations along the width and across the wall (m); peak value 1."""

    center_xy: tuple[float, float]
    angle_rad: float
    sigma_along_m: float
    sigma_across_m: float


def fit_door_kernel(points_xy: np.ndarray, *, min_sigma_m: float = 0.15) -> DoorKernel:
    """Kernel from a door's observed points: centre of the oriented bounding box, its orientation
    (principal axis), and half its width / thickness as deviations.

    Parameters
    ----------
    points_xy : ndarray, shape (k, 2)
        The door's observed points, metres.
    min_sigma_m : float, optional
        Floor of both deviations.

    Returns
    -------
    kernel : DoorKernel

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import fit_door_kernel
    >>> door = fit_door_kernel(np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5]]))  # a 1 m door in a wall at x = 1
    >>> door.center_xy, door.sigma_along_m, door.sigma_across_m
    ((1.0, 1.0), 0.5, 0.15)
    """
    mean = points_xy.mean(axis=0)
    if len(points_xy) > 1:
        evals, evecs = np.linalg.eigh(np.cov((points_xy - mean).T))
        axis = evecs[:, int(np.argmax(evals))]
    else:
        axis = np.array([1.0, 0.0])
    normal = np.array([-axis[1], axis[0]])
    along, across = (points_xy - mean) @ axis, (points_xy - mean) @ normal
    center = mean + axis * (along.max() + along.min()) / 2 + normal * (across.max() + across.min()) / 2
    return DoorKernel(
        center_xy=(float(center[0]), float(center[1])),
        angle_rad=float(np.arctan2(axis[1], axis[0])),
        sigma_along_m=max(float(np.ptp(along)) / 2, min_sigma_m),
        sigma_across_m=max(float(np.ptp(across)) / 2, min_sigma_m),
    )


def door_field(points_xy: np.ndarray, doors: list[DoorKernel]) -> np.ndarray:
    """Sum of the door kernels evaluated at points.

    Parameters
    ----------
    points_xy : ndarray, shape (..., 2)
        Points, metres.
    doors : list of DoorKernel

    Returns
    -------
    field : ndarray, shape (...)
        Each kernel peaks at 1.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import door_field, fit_door_kernel
    >>> door = fit_door_kernel(np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5]]))  # a 1 m door in a wall at x = 1
    >>> door_field(np.array([[1.0, 1.0], [1.15, 1.0], [2.0, 1.0]]), [door]).round(3)
    array([1.   , 0.607, 0.   ])
    """
    out = np.zeros(points_xy.shape[:-1])
    for door in doors:
        d = points_xy - np.asarray(door.center_xy)
        c, s = np.cos(door.angle_rad), np.sin(door.angle_rad)
        a = (d[..., 0] * c + d[..., 1] * s) / door.sigma_along_m
        b = (-d[..., 0] * s + d[..., 1] * c) / door.sigma_across_m
        out += np.exp(-0.5 * (a * a + b * b))
    return out


def door_crossing_edges(
    graph: NavGraph, doors: list[DoorKernel], *, threshold_m: float = 0.15, step_m: float = 0.0375
) -> np.ndarray:
    """Edges whose integral of the door field along the straight segment exceeds ``threshold_m``.

    A full crossing of a kernel integrates to sigma_across * sqrt(2 pi).

    Parameters
    ----------
    graph : NavGraph
    doors : list of DoorKernel
    threshold_m : float, optional
        Integral (metres of kernel value 1) above which an edge is cut.
    step_m : float, optional
        Sampling step along an edge.

    Returns
    -------
    cut : ndarray of bool, shape (n_edges,)

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import NavGraph, door_crossing_edges, fit_door_kernel
    >>> door = fit_door_kernel(np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5]]))  # a 1 m door in a wall at x = 1
    >>> g = NavGraph(np.array([[0.0, 1.0], [2.0, 1.0], [2.0, 2.0]]), np.array([[0, 1], [1, 2]]), np.array([2.0, 1.0]))
    >>> door_crossing_edges(g, [door])  # the first edge walks through the door
    array([ True, False])
    """
    cut = np.zeros(graph.n_edges, dtype=bool)
    if not doors or graph.n_edges == 0:
        return cut
    a, b = graph.xy[graph.edges[:, 0]], graph.xy[graph.edges[:, 1]]
    for door in doors:
        reach = 4 * max(door.sigma_along_m, door.sigma_across_m)
        centre = np.asarray(door.center_xy)
        t = np.clip(np.einsum("ij,ij->i", centre - a, b - a) / np.maximum(graph.weights, 1e-9) ** 2, 0, 1)
        near = np.flatnonzero(np.linalg.norm(a + t[:, None] * (b - a) - centre, axis=1) < reach)
        if near.size == 0:
            continue
        n = max(2, int(np.ceil(graph.weights[near].max() / step_m)) + 1)
        s = (np.arange(n) + 0.5) / n
        pts = a[near, None, :] + s[None, :, None] * (b[near] - a[near])[:, None, :]
        integral = door_field(pts, [door]).mean(axis=1) * graph.weights[near]
        cut[near[integral > threshold_m]] = True
    return cut


def segment_regions(
    graph: NavGraph, cut: np.ndarray, doors: list[DoorKernel], *, doorway_value: float = 0.05
) -> np.ndarray:
    """Region label per node: the components of the graph without its cut edges.

    Parameters
    ----------
    graph : NavGraph
    cut : ndarray of bool, shape (n_edges,)
        Door-crossing edges.
    doors : list of DoorKernel
    doorway_value : float, optional
        A component whose nodes all have a kernel value above this lies in a doorway.

    Returns
    -------
    labels : ndarray of int, shape (n_nodes,)
        0..k-1, ordered by each region's smallest (x, y) node; -1 for doorway components.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import NavGraph, door_crossing_edges, fit_door_kernel, segment_regions
    >>> door = fit_door_kernel(np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5]]))  # a 1 m door in a wall at x = 1
    >>> g = NavGraph(np.array([[0.0, 1.0], [2.0, 1.0], [2.0, 2.0]]), np.array([[0, 1], [1, 2]]), np.array([2.0, 1.0]))
    >>> segment_regions(g, door_crossing_edges(g, [door]), [door])
    array([0, 1, 1])
    """
    comp = graph.components(~cut)
    if graph.n_nodes == 0:
        return comp
    in_door = door_field(graph.xy, doors) > doorway_value
    k = int(comp.max()) + 1
    doorway_only = np.bincount(comp, weights=~in_door, minlength=k) == 0
    comp = np.where(doorway_only[comp], -1, comp)
    return _relabel(comp, graph.xy)


def merge_subregions(
    labels: np.ndarray,
    node_cells: np.ndarray,
    occupancy: np.ndarray,
    doorway: np.ndarray,
) -> np.ndarray:
    """Merge regions whose nodes fall in one 8-connected patch of FREE, non-``doorway`` cells
    (sub-regions of one room split by partial observation or furniture).

    Parameters
    ----------
    labels : ndarray of int, shape (n,)
        Region per node, -1 for none.
    node_cells : ndarray of int, shape (n, 2)
        The nodes' cells (ix, iy), as ``Grid.cell_of`` gives them.
    occupancy : ndarray of int, shape (nx, ny)
        The BEV grid.
    doorway : ndarray of bool, shape (nx, ny)
        Door-kernel cells (see ``doorway_mask``).

    Returns
    -------
    labels : ndarray of int, shape (n,)
        Merged labels, renumbered 0..k-1 in order; -1 kept.

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import FREE, merge_subregions
    >>> occ = np.full((4, 2), FREE, dtype=np.int8)
    >>> doorway = np.zeros((4, 2), dtype=bool)
    >>> merge_subregions(np.array([0, 1]), np.array([[0, 0], [3, 1]]), occ, doorway)
    array([0, 0])
    >>> doorway[2] = True  # a doorway splits the patch
    >>> merge_subregions(np.array([0, 1]), np.array([[0, 0], [3, 1]]), occ, doorway)
    array([0, 1])
    """
    if labels.size == 0 or labels.max() < 0:
        return labels
    patches, _ = ndimage.label((occupancy == FREE) & ~doorway, structure=np.ones((3, 3)))
    patch = patches[node_cells[:, 0], node_cells[:, 1]]
    parent = np.arange(int(labels.max()) + 1)

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    first_region: dict[int, int] = {}
    for lab, p in zip(labels.tolist(), patch.tolist()):
        if lab < 0 or p == 0:
            continue
        other = first_region.setdefault(p, lab)
        ra, rb = find(lab), find(other)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(i) for i in range(len(parent))])
    compact = np.searchsorted(np.unique(roots), roots)  # roots are the smallest member label: order kept
    return np.where(labels >= 0, compact[np.maximum(labels, 0)], -1)


def doorway_mask(
    shape: tuple[int, int],
    grid: Grid,
    doors: list[DoorKernel],
    *,
    value: float = 0.05,
) -> np.ndarray:
    """The cells where a door kernel exceeds ``value``.

    Parameters
    ----------
    shape : tuple of int
        (nx, ny) of the grid.
    grid : Grid
        Where the cells lie.
    doors : list of DoorKernel
    value : float, optional
        Kernel value above which a cell is in a doorway.

    Returns
    -------
    mask : ndarray of bool, shape ``shape``

    Examples
    --------
    >>> import numpy as np
    >>> from more_agent.mapping import Grid, doorway_mask, fit_door_kernel
    >>> door = fit_door_kernel(np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5]]))  # a 1 m door in a wall at x = 1
    >>> doorway_mask((4, 4), Grid(resolution_m=0.5), [door]).astype(int)
    array([[0, 0, 0, 0],
           [1, 1, 1, 1],
           [1, 1, 1, 1],
           [0, 0, 0, 0]])
    """
    mask = np.zeros(shape, dtype=bool)
    for door in doors:
        reach = max(door.sigma_along_m, door.sigma_across_m) * np.sqrt(2 * np.log(1 / value))
        lo, hi = grid.cell_range(np.asarray(door.center_xy) - reach, np.asarray(door.center_xy) + reach)
        lo, hi = np.maximum(lo, 0), np.minimum(hi + 1, shape)  # one cell of margin
        if (hi <= lo).any():
            continue
        centres = grid.xy_of(np.stack(list(np.mgrid[lo[0] : hi[0], lo[1] : hi[1]]), axis=-1))
        mask[lo[0] : hi[0], lo[1] : hi[1]] |= door_field(centres, [door]) > value
    return mask


def _relabel(labels: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Renumber non-negative labels 0..k-1 in lexicographic order of each label's first node by (x, y)."""
    order = np.lexsort((xy[:, 1], xy[:, 0]))
    seen: dict[int, int] = {}
    for i in order:
        lab = int(labels[i])
        if lab >= 0 and lab not in seen:
            seen[lab] = len(seen)
    lut = np.full(int(labels.max()) + 2 if labels.size else 1, -1)
    for old, new in seen.items():
        lut[old] = new
    return np.where(labels >= 0, lut[labels], -1)
