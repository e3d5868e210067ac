"""The scene-graph language encoding: prompt snapshots on a hand-made graph, filtering, name resolution."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from more_agent.llm import FilterResult, filter_messages
from more_agent.planners.language import LanguageOptions, SceneView, room_names, scene_view
from more_agent.planners.llm_planner import PLANNER_CONFIGS
from more_agent.scene_graph import Box3D, NavGraphData, ObjectNode, RegionNode, Relation, RobotNode, SceneGraph

SNAPSHOTS = Path(__file__).parent / "snapshots"
UPDATE = os.environ.get("MORE_AGENT_UPDATE_SNAPSHOTS") == "1"


def _obj(label: str, region: str | None, xy: tuple[float, float], *, open_: bool | None = None, held: bool = False) -> ObjectNode:
    x, y = xy
    return ObjectNode(
        id=label, category=label.rsplit(" ", 1)[0], instance_id=abs(hash(label)) % 1000, label=label, region_id=region,
        position=(x, y, 0.5), bbox=Box3D(min=(x - 0.2, y - 0.2, 0.0), max=(x + 0.2, y + 0.2, 1.0)), open=open_, held=held,
    )


def hand_made_graph() -> SceneGraph:
    """Kitchen (region_0), living room (region_2), an unlabelled region_10 with an unexplored area; a book in hand."""
    objects = [
        _obj("fridge A", "region_0", (1.0, 1.0), open_=True), _obj("apple A", "region_0", (1.0, 1.0)),
        _obj("table A", "region_0", (2.0, 1.0)), _obj("apple B", "region_0", (2.0, 1.0)),
        _obj("cabinet A", "region_0", (3.0, 1.0), open_=False), _obj("cabinet B", "region_0", (3.5, 1.0), open_=False),
        _obj("door A", "region_2", (4.0, 2.0), open_=True), _obj("sofa A", "region_2", (6.0, 2.0)),
        _obj("book A", None, (1.5, 1.5), held=True),
    ]
    regions = {
        "region_0": RegionNode(id="region_0", room_label="kitchen", centroid=(2.0, 1.0), nav_nodes=[0],
                               frontiers=[(0.5, 3.0)]),
        "region_2": RegionNode(id="region_2", room_label="living room", centroid=(6.0, 2.0), nav_nodes=[1],
                               frontiers=[]),
        "region_10": RegionNode(id="region_10", room_label=None, centroid=(9.0, 2.0), nav_nodes=[2],
                                frontiers=[(9.5, 3.0)]),
    }
    return SceneGraph(
        step=3, robot=RobotNode(position=(1.5, 1.5), region_id="region_0"),
        regions=regions, objects={o.id: o for o in objects},
        relations=[Relation(subject="apple A", predicate="inside", object="fridge A"),
                   Relation(subject="apple B", predicate="ontop", object="table A")],
        nav=NavGraphData(node_xy=np.array([[2.0, 1.0], [6.0, 2.0], [9.0, 2.0]]), edges=np.array([[0, 1], [1, 2]]),
                         weights=np.array([4.1, 3.0]), door_edges=np.array([True, False]),
                         node_region=["region_0", "region_2", "region_10"]),
    )


def _check_snapshot(name: str, text: str) -> None:
    path = SNAPSHOTS / f"{name}.txt"
    if UPDATE:
        path.write_text(text + "\n", encoding="utf-8")
    assert text + "\n" == path.read_text(encoding="utf-8"), f"{name}: text differs from {path}"


@pytest.mark.parametrize("planner", ["more", "moma-llm", "moma-llm-sr"])
def test_scene_text_snapshots(planner: str) -> None:
    view = scene_view(hand_made_graph(), PLANNER_CONFIGS[planner].language)
    _check_snapshot(f"scene_{planner}", view.text())


def test_filtered_scene_snapshot_keeps_supports_and_robot_room() -> None:
    view = scene_view(hand_made_graph(), LanguageOptions())
    kept = FilterResult(rooms={"living_room_0": ("door A",), "kitchen_0": ("apple A",)}, unknown_rooms=(), unknown_objects=())
    filtered = view.filtered(kept)
    _check_snapshot("scene_more_filtered", filtered.text())
    # fridge: apple's container; book: in the robot's hand, never filtered away
    assert [o.name for o in filtered.room("kitchen_0").objects] == ["floor", "apple A", "book A", "fridge A"]
    only_door = view.filtered(FilterResult(rooms={"living_room_0": ()}, unknown_rooms=(), unknown_objects=()),
                              always={view.robot_room})
    assert [r.name for r in only_door.rooms] == ["kitchen_0", "living_room_0"]
    assert [o.name for o in only_door.room("kitchen_0").objects] == ["floor", "book A"]  # floors and the hand always stay


def test_room_names_are_unique_and_stable() -> None:
    graph = hand_made_graph()
    assert room_names(graph) == {"region_0": "kitchen_0", "region_2": "living_room_0", "region_10": "unknown_room_0"}
    relabelled = graph.with_room_labels({"region_10": "kitchen"})
    assert room_names(relabelled)["region_10"] == "kitchen_1"


def test_instance_ids_and_classes() -> None:
    graph = hand_made_graph()
    more = scene_view(graph, LanguageOptions(instance_ids=True, spatial_relations=True))
    moma = scene_view(graph, LanguageOptions(instance_ids=False, spatial_relations=False))
    assert more.robot_room == "kitchen_0" and more.held == "book A" and moma.held == "book"
    assert more.resolve("kitchen_0", "apple B") == ("apple B",)
    assert set(moma.resolve("kitchen_0", "apple")) == {"apple A", "apple B"}
    assert moma.resolve("kitchen_0", "sofa") == ("sofa A",)  # wrong room: found anywhere
    assert more.resolve(None, "book A") == ("book A",) and more.resolve("kitchen_0", "unicorn A") == ()
    assert "book A" in more.object_names() and more.resolve("kitchen_0", "book A") == ("book A",)
    assert "book A [held by the robot]" in more.text().splitlines()[0]  # held: in the robot's room
    assert moma.names()["kitchen_0"] == ["floor", "apple", "book", "cabinet", "fridge", "table"]
    robot_elsewhere = graph.model_copy(update={"robot": RobotNode(position=(6.0, 2.0), region_id="region_2")})
    assert "book A [held by the robot]" in scene_view(robot_elsewhere, LanguageOptions()).room("living_room_0").text()
    assert more.resolve("kitchen_0", "floor") == ()  # floors are rooms' ground, not graph objects


def test_filter_prompt_carries_the_scene_text() -> None:
    view: SceneView = scene_view(hand_made_graph(), LanguageOptions())
    messages = filter_messages("put the apple in the fridge", view.text())
    assert view.text() in messages[-1]["content"]


def test_empty_graph_text() -> None:
    graph = hand_made_graph().model_copy(update={
        "regions": {}, "objects": {}, "relations": [], "robot": RobotNode(position=(0.0, 0.0), region_id=None),
    })
    view = scene_view(graph, LanguageOptions())
    assert view.text() == "nothing observed yet" and view.robot_room == "unknown"


def test_graph_stores_region_and_hand_once_and_rejects_contradictions() -> None:
    graph = hand_made_graph()
    assert [o.id for o in graph.objects_in("region_0")] == sorted(
        o.id for o in graph.objects.values() if o.region_id == "region_0")
    assert graph.objects_in("region_10") == [] and graph.held_object is not None and graph.held_object.id == "book A"
    data = graph.model_dump()
    for label, region, held, problem in [("apple A", None, False, "held=False with region None"),
                                         ("sofa A", "region_7", False, "held=False with region 'region_7'"),
                                         ("sofa A", "region_2", True, "holds one object at most")]:
        data = graph.model_dump()
        data["objects"][label].update(region_id=region, held=held)
        with pytest.raises(ValueError, match=problem):
            SceneGraph.model_validate(data)
