"""Ground-truth navigation grid: free space, inflation, door blocking, shortest paths, caching."""

from __future__ import annotations

import math

import numpy as np
from skimage.graph import MCP_Geometric

from more_agent.sim.labels import InstanceLabels
from more_agent.sim.navgrid import NavConfig, blocking_door, free_cells, nav_grid, reachable, shortest_path
from more_agent.sim.paths import NavGrid, reaches
from more_agent.sim.scene import Door, Furniture, Room, Scene, Wall
from more_agent.sim.world import World, WorldObject


def two_room_scene(door_open: bool = True, door_width: float = 0.9) -> Scene:
    """Kitchen (x 0..4.95) and living room (x 5.05..10), 4 m deep, joined by one door at (5, 2)."""
    half = door_width / 2
    return Scene(
        name="two_rooms", bounds=(-0.1, -0.1, 10.1, 4.1),
        rooms=[Room(id="kitchen_0", type="kitchen", bounds=(0, 0, 4.95, 4)),
               Room(id="living_room_0", type="living_room", bounds=(5.05, 0, 10, 4))],
        walls=[Wall(bounds=(-0.1, -0.1, 10.1, 0)), Wall(bounds=(-0.1, 4, 10.1, 4.1)),
               Wall(bounds=(-0.1, 0, 0, 4)), Wall(bounds=(10, 0, 10.1, 4)),
               Wall(bounds=(4.95, 0, 5.05, 2 - half)), Wall(bounds=(4.95, 2 + half, 5.05, 4))],
        doors=[Door(id="door_0", rooms=("kitchen_0", "living_room_0"), center=(5, 2), width=door_width, axis="y",
                    open=door_open)],
        furniture=[
            Furniture(id="fridge_0", category="fridge", room="kitchen_0", center=(0.45, 3.5, 0.9), size=(0.8, 0.8, 1.8),
                      openable=True),
            Furniture(id="table_0", category="table", room="living_room_0", center=(7.5, 2, 0.4), size=(1.5, 0.9, 0.8)),
            Furniture(id="cabinet_0", category="bottom_cabinet", room="living_room_0", center=(9.6, 0.4, 0.45),
                      size=(0.7, 0.7, 0.9), openable=True),
        ],
    )


def two_room_world(door_open: bool = True) -> World:
    """The two-room scene with an apple in the closed fridge, a bowl on the table, a box on the kitchen floor."""
    world = World.from_scene(two_room_scene(door_open))
    for name, size in [("apple_0", 0.08), ("bowl_0", 0.2), ("box_0", 0.3)]:
        world.add(WorldObject(name=name, category=name[:-2], kind="item", center=np.zeros(3), size=np.full(3, size)))
    world.place("apple_0", "fridge_0", "inside")
    world.place("bowl_0", "table_0", "ontop")
    world.place_on_floor_at("box_0", "floor_kitchen_0", (3.0, 3.0))
    world.set_robot_pose(2.5, 1.0, 0.0)
    return world


def labelled(world: World) -> InstanceLabels:
    """Labels for every object of ``world``, as after a walk that saw them all ('fridge A')."""
    labels = InstanceLabels()
    labels.assign_all(world)
    return labels


def test_free_space_excludes_walls_furniture_and_keeps_clearance():
    grid = nav_grid(two_room_world())
    assert grid.is_free(2.5, 1.0)
    assert not grid.is_free(5.0, 1.0)          # wall
    assert not grid.is_free(7.5, 2.0)          # table
    assert not grid.is_free(7.5, 2.45 + 0.1)   # within the robot radius of the table
    assert grid.is_free(7.5, 2.45 + 0.35)
    assert not grid.is_free(20.0, 2.0)         # outside the scene


def test_a_footprint_thinner_than_a_cell_blocks_the_grid_as_it_blocks_the_base():
    """A room divider 2 cm thick lying between two columns of cell centres blocked no cell (putting_out_condiments
    seed 0's dividers, 1-4 cm): the magic actions' paths crossed it where the base's own moves are refused."""
    grid = nav_grid(two_room_world())
    res, x_origin = grid.resolution_m, grid.origin_xy[0]
    centre = x_origin + (math.floor((8.2 - x_origin) / res) + 0.5) * res  # a column of centres near x = 8.2 m
    x0, x1 = centre + 0.3 * res, centre + 0.6 * res  # between that column and the next
    scene = two_room_scene()
    scene.furniture.append(
        Furniture(id="room_divider_0", category="room_divider", room="living_room_0",
                  center=((x0 + x1) / 2, 2.0, 0.9), size=(x1 - x0, 4.0, 1.8))
    )
    world = World.from_scene(scene)
    world.set_robot_pose(2.5, 1.0, 0.0)
    assert reachable(two_room_world(), (2.5, 1.0), (9.5, 2.0))
    assert not reachable(world, (2.5, 1.0), (9.5, 2.0))  # the divider spans the living room
    assert reachable(world, (2.5, 1.0), (6.5, 3.5))


def test_open_door_connects_rooms_and_closed_door_blocks():
    world = two_room_world(door_open=True)
    assert reachable(world, (2.5, 1.0), (8.0, 3.5))
    world.set_open("door_0", False)
    assert not reachable(world, (2.5, 1.0), (8.0, 3.5))
    assert blocking_door(world, (2.5, 1.0), [(8.0, 3.5)]) == "door_0"
    assert blocking_door(world, (2.5, 1.0), [(1.0, 1.0)]) is None


def test_narrow_door_still_passable_with_default_radius():
    world = World.from_scene(two_room_scene(door_width=0.6))
    assert reachable(world, (2.5, 1.0), (8.0, 3.5))
    assert not reachable(world, (2.5, 1.0), (8.0, 3.5), NavConfig(robot_radius_m=0.35))


def test_shortest_path_goes_through_the_door_and_picks_nearest_goal():
    grid = nav_grid(two_room_world())
    path = shortest_path(grid, (2.5, 1.0), [(9.0, 3.5), (6.0, 1.0)])
    assert path.found and path.goal_index == 1
    assert path.waypoints[0] == (2.5, 1.0) and path.waypoints[-1] == (6.0, 1.0)
    assert any(abs(x - 5.0) < 0.3 and abs(y - 2.0) < 0.45 for x, y in path.waypoints)  # via the doorway
    assert 3.5 < path.length_m < 5.0
    assert not shortest_path(grid, (2.5, 1.0), [(7.5, 2.0)]).found  # goal inside the table


def test_a_grid_searched_again_finds_what_a_fresh_grid_finds():
    """A grid keeps its path search between searches (``NavGrid._mcp``): each search starts afresh, so the
    searches before it change nothing."""
    world = two_room_world()
    grid = nav_grid(world)
    shortest_path(grid, (6.0, 1.0), [(2.5, 1.0)])
    shortest_path(grid, (9.0, 3.5), [(7.5, 2.0), (2.5, 3.0)])
    again = shortest_path(grid, (2.5, 1.0), [(9.0, 3.5), (6.0, 1.0)])
    fresh = shortest_path(nav_grid(two_room_world()), (2.5, 1.0), [(9.0, 3.5), (6.0, 1.0)])
    assert again.found and again == fresh


def test_reaches_says_what_the_search_finds_without_searching():
    """``reaches`` (components of the free cells) against ``shortest_path(...).found`` (the search itself) on
    random rasters: corridors that touch only at a corner, starts off the free cells (snapped), goals off the
    free cells or off the grid."""
    corner = np.zeros((4, 4), dtype=bool)  # two free cells that touch only at a corner: the search steps across
    corner[1, 1] = corner[2, 2] = True
    rng = np.random.default_rng(7)
    for trial in range(60):
        free = corner if trial == 0 else rng.random((int(rng.integers(3, 25)), int(rng.integers(3, 25)))) < 0.5
        grid = NavGrid(origin_xy=(-1.0, 2.0), resolution_m=0.5, free=free, closed_doors=frozenset(), door_cells={})
        x1, y1 = -1.0 + 0.5 * free.shape[0], 2.0 + 0.5 * free.shape[1]
        for _ in range(10):
            start = (float(rng.uniform(-1.0, x1)), float(rng.uniform(2.0, y1)))
            goals = [
                (float(rng.uniform(-2.0, x1 + 1)), float(rng.uniform(1.0, y1 + 1))) for _ in range(rng.integers(0, 4))
            ]
            assert reaches(grid, start, goals) == shortest_path(grid, start, goals).found, (trial, start, goals)
    grid = NavGrid(origin_xy=(0.0, 0.0), resolution_m=1.0, free=corner, closed_doors=frozenset(), door_cells={})
    assert reaches(grid, (1.5, 1.5), [(2.5, 2.5)]) and shortest_path(grid, (1.5, 1.5), [(2.5, 2.5)]).found
    assert not reaches(grid, (1.5, 1.5), [(0.5, 0.5), (9.0, 9.0)])  # a blocked goal, one off the grid
    open_grid = NavGrid(origin_xy=(0.0, 0.0), resolution_m=1.0, free=np.ones((3, 3), dtype=bool), closed_doors=frozenset(),
                        door_cells={})
    assert not reaches(open_grid, (1.5, 1.5), [(9.0, 9.0)])  # off the grid, though the nearest cell is free


def test_the_search_over_the_free_cells_box_finds_the_whole_raster_s_path():
    """``NavGrid._mcp`` searches only the bounding box of the free cells: on random rasters whose free cells
    lie anywhere (touching the raster's edge or far from it), each path is the one a search over the whole
    raster traces, cell for cell, at the same cost."""
    rng = np.random.default_rng(11)
    for trial in range(80):
        nx, ny = int(rng.integers(4, 30)), int(rng.integers(4, 30))
        free = np.zeros((nx, ny), dtype=bool)
        x0, y0 = int(rng.integers(0, nx - 2)), int(rng.integers(0, ny - 2))
        x1, y1 = int(rng.integers(x0 + 2, nx + 1)), int(rng.integers(y0 + 2, ny + 1))
        free[x0:x1, y0:y1] = rng.random((x1 - x0, y1 - y0)) < 0.7
        cells = np.argwhere(free)
        if len(cells) < 2:
            continue
        grid = NavGrid(origin_xy=(0.0, 0.0), resolution_m=1.0, free=free, closed_doors=frozenset(), door_cells={})
        whole = MCP_Geometric(np.where(free.T, 1.0, np.inf))
        for _ in range(5):
            start, *goals = cells[rng.choice(len(cells), size=int(rng.integers(2, 5)))]
            path = shortest_path(grid, tuple(start + 0.5), [tuple(g + 0.5) for g in goals])
            cum, _ = whole.find_costs([start[::-1]], [g[::-1] for g in goals], find_all_ends=False)
            reached = [(cum[g[1], g[0]], i) for i, g in enumerate(goals) if np.isfinite(cum[g[1], g[0]])]
            assert path.found == bool(reached), trial
            if reached:
                cost, k = min(reached)
                assert path.goal_index == k and path.length_m == cost, trial
                assert path.cells == [(int(ix), int(iy)) for iy, ix in whole.traceback(tuple(goals[k][::-1]))], trial


def test_grid_cached_per_door_state():
    world = two_room_world()
    first = nav_grid(world)
    assert nav_grid(world) is first
    world.set_open("door_0", False)
    closed = nav_grid(world)
    assert closed is not first and closed.closed_doors == frozenset({"door_0"})
    world.set_open("door_0", True)
    assert nav_grid(world) is first


def test_grid_is_indexed_x_first_and_cells_round_trip():
    grid = nav_grid(two_room_world())
    lo_x, lo_y, hi_x, hi_y = grid.bounds(grid.shape)
    assert hi_x - lo_x > hi_y - lo_y  # the two rooms lie side by side along x: the first axis is x
    cell = grid.cell_at(2.5, 1.0)
    assert grid.free[cell] and math.dist(grid.centre(cell), (2.5, 1.0)) <= grid.resolution_m / math.sqrt(2)
    assert not grid.free[grid.cell_at(7.5, 2.0)]  # the table
    assert grid.cell_at(-100.0, 100.0) == (0, grid.shape[1] - 1)  # clipped


def test_free_cells_walk_row_by_row():
    mask = np.array([[True, True], [True, False]])  # [ix, iy]
    assert free_cells(mask).tolist() == [[0, 0], [1, 0], [0, 1]]
