"""Box-world test scenes and an exploration helper for the builder tests."""

from __future__ import annotations

import numpy as np

from more_agent.mapping import MappingConfig
from more_agent.scene_graph import InstanceInfo, SceneGraphBuilder
from tests.scene_graph.boxworld import CLASSES, Box, camera_pose, intrinsics, render, walls_x, walls_y

SIZE = 128


def two_rooms(*, door_observable: bool = True, cabinet: bool = True) -> tuple[list[Box], dict[int, InstanceInfo]]:
    """Room A x in [0, 4], room B x in [4.15, 8.15], y in [0, 4]; door opening y in [1.55, 2.45]."""
    boxes = [Box((-0.2, -0.2, -0.05), (8.4, 4.2, 0.0), "floor")]
    boxes += walls_y(-0.15, -0.15, 8.3) + walls_y(4.0, -0.15, 8.3)
    boxes += walls_x(-0.15, -0.15, 4.15) + walls_x(8.15, -0.15, 4.15)
    boxes += walls_x(4.0, 0.0, 4.0, openings=[(1.55, 2.45)])
    boxes.append(Box((4.0, 1.55, 2.1), (4.15, 2.45, 2.6), "door" if door_observable else "wall", 1 if door_observable else 0))
    boxes += [
        Box((1.0, 2.8, 0), (1.8, 3.6, 0.75), "table", 3),
        Box((1.3, 3.1, 0.75), (1.45, 3.25, 0.85), "apple", 4),
        Box((6.5, 3.0, 0), (7.3, 3.7, 0.75), "table", 5),
    ]
    if cabinet:
        boxes.append(Box((3.45, 0.3, 0), (3.95, 0.9, 1.0), "cabinet", 2))
    infos = {
        1: InstanceInfo(label="door A", category="door", open=True),
        2: InstanceInfo(label="cabinet A", category="cabinet", open=False),
        3: InstanceInfo(label="table A", category="table"),
        4: InstanceInfo(label="apple A", category="apple"),
        5: InstanceInfo(label="table B", category="table"),
    }
    return boxes, infos


def house_and_garden() -> tuple[list[Box], dict[int, InstanceInfo]]:
    """House x in [0, 4] with a window (y 0.5..1.5, sill 0.9 m) and an open door (y 3.0..3.9) in
    its east wall; lawn east of it. A tall cabinet stands inside, right behind the window."""
    boxes = [Box((-0.2, -0.2, -0.05), (4.15, 4.2, 0.0), "floor"), Box((4.15, -1.5, -0.05), (9.0, 5.5, 0.0), "lawn")]
    boxes += walls_y(-0.15, -0.15, 4.15) + walls_y(4.0, -0.15, 4.15) + walls_x(-0.15, -0.15, 4.15)
    boxes += walls_x(4.0, 0.0, 4.0, openings=[(0.5, 1.5), (3.0, 3.9)])
    boxes += [
        Box((4.0, 0.5, 0.0), (4.15, 1.5, 0.9), "wall"),
        Box((4.0, 0.5, 2.0), (4.15, 1.5, 2.6), "wall"),
        Box((4.0, 3.0, 2.1), (4.15, 3.9, 2.6), "door", 1),
        Box((2.6, 0.7, 0.0), (3.1, 1.3, 1.5), "cabinet", 2),
    ]
    infos = {
        1: InstanceInfo(label="door A", category="door", open=True),
        2: InstanceInfo(label="cabinet A", category="cabinet", open=False),
    }
    return boxes, infos


def explore(builder: SceneGraphBuilder, boxes: list[Box], infos: dict[int, InstanceInfo],
            positions: list[tuple[float, float]], n_yaw: int = 12) -> None:
    """A full turn in place at each position."""
    K = intrinsics(SIZE)
    for x, y in positions:
        for yaw in np.linspace(0, 2 * np.pi, n_yaw, endpoint=False):
            T = camera_pose(x, y, yaw)
            depth, sem, inst = render(boxes, K, T, SIZE)
            builder.integrate(depth, sem, inst, K, T, infos, (x, y))


def new_builder(**config: object) -> SceneGraphBuilder:
    return SceneGraphBuilder(class_names=CLASSES, config=MappingConfig(initial_extent_m=12.0, **config))
