"""Voronoi graph: nodes on free cells with clearance, metric edges, passes doors."""

import numpy as np
from scipy import ndimage

from more_agent.mapping import Grid, voronoi_graph
from more_agent.mapping.occupancy import FREE, OCCUPIED, UNKNOWN


def _cells(xy: np.ndarray, origin, res: float) -> np.ndarray:
    return np.floor((xy - np.asarray(origin)) / res).astype(int)


def test_nodes_lie_on_free_cells_with_clearance_and_edges_are_metric() -> None:
    res, origin = 0.075, (-3.0, 2.0)
    occ = np.full((100, 80), UNKNOWN, dtype=np.int8)
    occ[10:90, 10:70] = OCCUPIED
    occ[12:88, 12:68] = FREE
    occ[50:52, 12:68] = OCCUPIED
    occ[50:52, 35:47] = FREE  # door gap
    g = voronoi_graph(occ, Grid(origin_xy=origin, resolution_m=res), inflation_m=0.15)
    cells = _cells(g.xy, origin, res)
    assert (occ[cells[:, 0], cells[:, 1]] == FREE).all()
    clearance = ndimage.distance_transform_edt(occ == FREE) * res
    assert (clearance[cells[:, 0], cells[:, 1]] > 0.15).all()
    np.testing.assert_allclose(g.weights, np.linalg.norm(g.xy[g.edges[:, 0]] - g.xy[g.edges[:, 1]], axis=1))
    assert len(np.unique(g.components())) == 1  # the door keeps both rooms connected
    assert (g.xy[:, 0] < origin[0] + 50 * res).any() and (g.xy[:, 0] > origin[0] + 52 * res).any()


def test_empty_and_obstacle_only_maps_give_empty_graphs() -> None:
    assert voronoi_graph(np.zeros((20, 20), np.int8), Grid(resolution_m=0.1)).n_nodes == 0
    assert voronoi_graph(np.full((20, 20), OCCUPIED, np.int8), Grid(resolution_m=0.1)).n_nodes == 0


def test_generated_apartment_graph_is_connected() -> None:
    from more_agent.sim.navgrid import nav_grid
    from more_agent.sim.scenes import get_scene
    from more_agent.sim.world import World

    world = World.from_scene(get_scene("Rs_int", 0))
    for door in world.scene.doors:
        world.set_open(door.id, True)
    free = nav_grid(world).free.T  # navgrid rows are y; occupancy grids index (x, y)
    occ = np.where(free, FREE, OCCUPIED).astype(np.int8)
    g = voronoi_graph(occ, Grid(resolution_m=0.075))
    assert g.n_nodes > 100
    comps = np.bincount(g.components())
    assert comps.max() > 0.95 * g.n_nodes
