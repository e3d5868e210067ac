"""Noisy perception on a real (small) task, as a planner drives it (``NoisyRobot`` around the simulator's
robot): it replays exactly, names what it mistakes with labels of the category it sees, and a magic
action on such a label acts on the real object; the world stays exact."""

from __future__ import annotations

import math
from pathlib import Path

from more_agent.perception.model import NoisyPerception, perception_for
from more_agent.perception.robot import NoisyRobot
from more_agent.planners.policies import Embodiment, go_to_and
from more_agent.scene_graph import SceneGraph
from more_agent.sim.env import SimRobot
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.scene import load_scene
from tests.sim.test_navgrid import labelled, two_room_world

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"


def looked_around(perception: str) -> tuple[TaskInstance, Embodiment, SceneGraph, NoisyPerception | None]:
    """The kitchen task after the initial full turn, perceived in mode ``perception``."""
    inst = instantiate_in_scene(TASK, load_scene(KITCHEN), seed=0, start="task-room")
    noise = perception_for(perception, inst.world, inst.labels, 0, TASK)
    robot = SimRobot(inst.world, labels=inst.labels)
    body = Embodiment(robot if noise is None else NoisyRobot(robot, noise))
    body.look_around()
    return inst, body, body.build(), noise


def test_ground_truth_builds_no_perception_and_all_kinds_off_neither() -> None:
    inst = instantiate_in_scene(TASK, load_scene(KITCHEN), seed=0, start="task-room")
    assert perception_for("gt", inst.world, inst.labels, 0, TASK) is None
    off = "noisy:confusion=0,miss=0,fragment=0,merge=0,depth=0,drift=0,room=0"
    assert perception_for(off, inst.world, inst.labels, 0, TASK) is None


def test_a_noisy_episode_replays_exactly() -> None:
    runs = [looked_around("noisy:miss=0.5,merge=0.3,fragment=0.3,confusion=0.3") for _ in range(2)]
    (_, a, ga, na), (_, b, gb, nb) = runs
    assert ga.model_dump_json() == gb.model_dump_json()
    assert na is not None and nb is not None and na.aliases and na.aliases == nb.aliases
    assert a.observed == b.observed and na.observed() == nb.observed()


def test_confused_objects_get_a_label_of_the_category_seen_and_act_as_the_real_object() -> None:
    inst, body, graph, noise = looked_around("noisy:confusion=1,miss=0,fragment=0,merge=0,depth=0,drift=0,room=0")
    assert noise is not None and noise.aliases
    for label, name in noise.aliases.items():
        real = inst.world.get(name)
        node = graph.objects.get(label)
        assert node is None or node.category == label.rsplit(" ", 1)[0] != real.category
        assert noise.real_label(label) == inst.labels.label(name) and inst.labels.find(label) is None  # no object's
        assert inst.labels.label(name) not in graph.objects and name not in noise.observed()  # seen, but not as itself
    item = next(
        (
            graph.objects[lbl]
            for lbl, n in noise.aliases.items()
            if lbl in graph.objects and inst.world.get(n).kind == "item"
        ),
        None,
    )
    assert item is not None, "the kitchen's first view holds a confusable item"
    real = noise.aliases[item.label]
    result = go_to_and(body, body.build(), "grasp", item)
    assert result.ok, result.feedback
    assert inst.world.robot.held == real  # the magic action took the real object


def test_missed_objects_leave_the_graph_and_the_observed_set() -> None:
    _, _, gt_graph, _ = looked_around("gt")
    _, _, graph, noise = looked_around("noisy:miss=1,confusion=0,fragment=0,merge=0,depth=0,drift=0,room=0")
    assert noise is not None and len(graph.objects) < len(gt_graph.objects)
    assert set(graph.objects) < set(gt_graph.objects)  # nothing made up: the rest are named as themselves


def test_feedback_names_every_confused_object_as_perceived() -> None:
    """A message about an action (the held item when placing, a support) never shows the real label of an
    object perception names otherwise: the planner would learn what it never saw."""
    inst, _, _, noise = looked_around("noisy:confusion=1,miss=0,fragment=0,merge=0,depth=0,drift=0,room=0")
    assert noise is not None and len(noise.aliases) >= 2
    (fresh, name), (other_fresh, other) = list(noise.aliases.items())[:2]
    real, other_real = inst.labels.label(name), inst.labels.label(other)
    text = f"cannot place {real} on {other_real}; {real}B stays"  # a longer label is not touched
    assert noise.perceived_text(text, {}) == f"cannot place {fresh} on {other_fresh}; {real}B stays"
    assert noise.perceived_text(text, {real: "bowl Z"}).startswith("cannot place bowl Z on ")  # the target's label


class _Renamed:
    """The two calls ``NoisyRobot.act`` makes of its perception, for a perception that saw door A as
    wardrobe B: the made-up label turned into the real one, and back in what the action reports."""

    def real_label(self, label: str) -> str:
        return "door A" if label == "wardrobe B" else label

    def perceived_text(self, text: str, acted_on: dict[str, str]) -> str:
        return text.replace("door A", "wardrobe B")


def test_the_door_in_the_way_is_named_as_perceived() -> None:
    """A planner is told the door in its way by the label its perception gave it, as in the feedback."""
    world = two_room_world(door_open=False)
    robot = NoisyRobot(SimRobot(world, labels=labelled(world)), _Renamed())  # type: ignore[arg-type]
    blocked = robot.act("grasp", "bowl A")
    assert blocked.blocking == "wardrobe B" and "wardrobe B" in blocked.feedback and "door A" not in blocked.feedback


def test_what_opening_reveals_counts_as_perceived_though_no_frame_shows_it() -> None:
    """The planner is told of the apple in the fridge it opened (``Observation.revealed``) while the camera
    looks away; the perception's record of what was perceived, rTP's observed set, must say so too."""
    world = two_room_world()
    labels = InstanceLabels()
    labels.reserve(world.get("fridge_0"))
    noise = perception_for("noisy:confusion=0,miss=0,fragment=0,merge=0,drift=0,room=0", world, labels, 0, TASK)
    assert noise is not None
    robot = NoisyRobot(SimRobot(world, labels=labels), noise)
    assert robot.act("open", "fridge A").ok
    x, y, yaw = robot.pose
    world.set_robot_pose(x, y, yaw + math.pi)
    seen = robot.sense(["fridge A"])
    apple = world.get("apple_0").instance_id
    assert apple in seen.revealed and apple not in seen.frame.instance
    assert "apple_0" in noise.observed()
