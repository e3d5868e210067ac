"""The grounded planner: goal knowledge without world state, solving a kitchen task through the scene graph."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from more_agent.eval.episode import run_episode
from more_agent.planners.base import EpisodeContext, default_planner, make_planner
from more_agent.planners.grounded import EXPLORES_WHERE_THE_TASK_IS, GroundedPlanner
from more_agent.planners.room_types import likely_room_type
from more_agent.planners.task_goal import task_goal
from more_agent.records import EpisodeSpec
from more_agent.scene_graph import SceneGraph
from more_agent.scene_graph.model import Box3D, NavGraphData, ObjectNode, RegionNode, RobotNode
from more_agent.sim.goals import GoalChecker, GoalStatus, Literal
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


class BlindGoals(GoalChecker):
    """The real goal checker, except that checking the goal (privileged) fails the test."""

    def check(self, world: World | None = None) -> GoalStatus:
        raise AssertionError("the grounded planner checked the goal")


@pytest.fixture(scope="module")
def kitchen() -> TaskInstance:
    return instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)


def test_task_goal_is_over_scopes_with_the_labels_the_description_names(kitchen: TaskInstance) -> None:
    goal = task_goal(kitchen, GoalChecker(kitchen))
    world_names = set(kitchen.world.objects)
    assert goal.options and all(not set(lit.args) & world_names for opt in goal.options for lit in opt)
    assert goal.named == {"electric_refrigerator.n.01_1": "fridge A", "cabinet.n.01_1": "bottom_cabinet A"}
    assert "fridge" in goal.categories["electric_refrigerator.n.01_1"]
    assert "egg.n.02_1" not in goal.named  # the description says "dairy", not which instance


def test_grounded_solves_the_kitchen_task_without_checking_the_goal(kitchen: TaskInstance) -> None:
    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    actions = []
    for _ in range(50):
        planner.observe()
        action = planner.decide()
        result = planner.execute(action)
        actions.append((action.name, action.arguments, result.ok))
        if action.is_done:
            break
    assert actions[-1][0] == "done" and GoalChecker(kitchen).check(kitchen.world).all_met, actions
    assert all(name != "go_to_and_place_inside" or ok for name, _, ok in actions)  # never places into a closed container


def test_grounded_episode_is_deterministic_and_records_no_failure() -> None:
    spec = EpisodeSpec(task="putting_shopping_away", scene="Rs_int", seed=0, planner="grounded")
    first, second = run_episode(spec), run_episode(spec)
    assert first.success and first.failure is None and first.error is None
    assert [a.model_dump() for a in first.actions] == [a.model_dump() for a in second.actions]
    assert first.timings["plan"] / first.high_level_steps < 0.05  # the planner itself: milliseconds a step


def test_registry_and_default_without_llm() -> None:
    assert make_planner("grounded").name == "grounded"
    assert default_planner(None) in ("grounded", "more")  # 'more' only where an LLM is configured


def test_room_types_from_furniture() -> None:
    assert likely_room_type(["fridge", "oven", "bottom_cabinet_no_top"]) == "kitchen"
    assert likely_room_type(["toilet"]) == "bathroom" and likely_room_type(["sofa", "coffee_table"]) == "living_room"
    assert likely_room_type(["unicorn"]) is None  # no room type lists it: no evidence


def _two_room_graph(robot_xy: tuple[float, float]) -> SceneGraph:
    """A region holding a checkout (typed a bathroom, as a store may be) and a kitchen, both with unexplored areas."""
    def obj(label: str, category: str, region: str, xy: tuple[float, float]) -> ObjectNode:
        box = Box3D(min=(xy[0] - 0.2, xy[1] - 0.2, 0.0), max=(xy[0] + 0.2, xy[1] + 0.2, 0.9))
        return ObjectNode(id=label, category=category, instance_id=len(label), label=label, region_id=region,
                          position=(xy[0], xy[1], 0.45), bbox=box, open=False if category == "fridge" else None)

    objects = [obj("checkout_counter A", "checkout_counter", "region_0", (2.0, 2.0)),
               obj("fridge A", "fridge", "region_1", (8.0, 2.0))]
    regions = {
        "region_0": RegionNode(id="region_0", centroid=(2.0, 2.0), nav_nodes=[0], object_ids=["checkout_counter A"],
                               frontiers=[(0.0, 4.0)]),
        "region_1": RegionNode(id="region_1", centroid=(8.0, 2.0), nav_nodes=[1], object_ids=["fridge A"],
                               frontiers=[(9.0, 4.0)]),
    }
    nav = NavGraphData(node_xy=np.array([[2.0, 2.0], [8.0, 2.0]]), edges=np.array([[0, 1]]), weights=np.array([6.0]),
                       door_edges=np.array([False]), node_region=["region_0", "region_1"])
    return SceneGraph(step=0, robot=RobotNode(position=robot_xy, region_id="region_1" if robot_xy[0] > 5 else "region_0"),
                      regions=regions, objects={o.label: o for o in objects}, relations=[], nav=nav)


def test_search_stays_where_the_task_objects_were_found_before_the_likelier_room_type(kitchen: TaskInstance) -> None:
    """An apple is missing; the kitchen is the likelier room type for it, but the ground beef the
    goal also moves was found in the other region: that one is explored (up to its larger share)."""
    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.graph = _two_room_graph((8.0, 2.0))
    planner.room_types = {"region_0": "bathroom", "region_1": "kitchen"}
    planner.explored.clear()
    planner.found_in = {"checkout_counter A": "region_0", "fridge A": "region_1"}
    cats = ["apple"]
    planner.bound = {"cabinet.n.01_1": "checkout_counter A"}  # where things go is not where they are
    assert planner._room_to_explore(cats) == "region_1"
    planner.bound = {"pack__of__ground_beef.n.01_1": "checkout_counter A"}
    assert planner._room_to_explore(cats) == "region_0"
    planner.explored["region_0"] = EXPLORES_WHERE_THE_TASK_IS - 1
    assert planner._room_to_explore(cats) == "region_0"
    planner.explored["region_0"] = EXPLORES_WHERE_THE_TASK_IS  # its share is spent: the others come first
    assert planner._room_to_explore(cats) == "region_1"


def test_containers_here_are_opened_only_where_the_search_would_look_anyway(kitchen: TaskInstance) -> None:
    """Looking for canned food from the kitchen: with nothing of the task seen elsewhere the kitchen's
    closed fridge is opened first; once a task object stands in the other region, the robot goes
    exploring there instead of opening what is near."""
    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.graph = _two_room_graph((8.0, 2.0))
    planner.room_types = {"region_0": "bathroom", "region_1": "kitchen"}
    planner.names = {"region_0": "bathroom_0", "region_1": "kitchen_0"}
    planner.seen = dict(planner.graph.objects)
    planner.explored.clear()
    planner.looked_into, planner.bound = set(), {}
    wanted = Literal("inside", ("canned_food.n.01_1", "cabinet.n.01_1"))
    step = planner._search(wanted, None)
    assert (step.action.name, step.target) == ("go_to_and_open", "fridge A")
    planner.found_in = {"checkout_counter A": "region_0"}
    planner.bound = {"pack__of__ground_beef.n.01_1": "checkout_counter A"}  # found in the other region
    step = planner._search(wanted, None)
    assert (step.action.name, step.region) == ("explore", "region_0")
    planner.explored.update({"region_0": EXPLORES_WHERE_THE_TASK_IS, "region_1": 3})  # both had their share
    step = planner._search(wanted, None)
    assert (step.action.name, step.target) == ("go_to_and_open", "fridge A")
    planner.looked_into.add("fridge A")  # nothing closed left: explore again, where the task is
    step = planner._search(wanted, None)
    assert (step.action.name, step.region) == ("explore", "region_0")
