"""The grounded planner: goal knowledge without world state, solving a kitchen task through the scene graph."""

from __future__ import annotations

from pathlib import Path

import pytest

from more_agent.eval.episode import run_episode
from more_agent.planners.base import HighLevelAction, default_planner, make_planner
from more_agent.planners.grounded import (
    FLOOR, FRUITLESS_EXPLORES, GROUND_M, OPENS_BEFORE_EXPLORING, GroundedPlanner, _on_floor, _Step, far_frontiers,
)
from more_agent.planners.room_types import is_furniture, likely_room_type
from more_agent.planners.task_goal import task_goal
from more_agent.records import EpisodeSpec
from more_agent.sim.actions import ActionResult, FailureReason
from more_agent.sim.catalog import can_hold_things
from more_agent.sim.goals import GoalChecker, GoalStatus, Literal
from more_agent.sim.instantiate import TaskInstance, instantiate, instantiate_in_scene
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
    from more_agent.planners.base import EpisodeContext

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


def test_explore_goes_to_the_frontiers_far_from_the_robots_path() -> None:
    frontiers = [(1.0, 0.0), (10.0, 0.0), (0.0, 9.0), (4.0, 0.0)]
    path = [(0.0, 0.0), (0.5, 0.0)]
    assert far_frontiers(frontiers, path) == ((10.0, 0.0), (0.0, 9.0))  # 4 m is under half the farthest gap
    assert far_frontiers([], path) == ()


def test_explore_goes_to_the_frontiers_with_the_most_unseen_floor_in_range() -> None:
    import numpy as np

    from more_agent.mapping import FREE, UNKNOWN
    from more_agent.planners.base import EpisodeContext
    from more_agent.scene_graph import OccupancyMap

    kitchen = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)  # untouched by other tests
    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.observe()
    cells = np.full((400, 200), FREE, dtype=np.int8)  # 40 m x 20 m at 0.1 m, corner at the origin
    cells[300:, :] = UNKNOWN  # a large unseen area east of x = 30 m
    cells[:20, 95:105] = UNKNOWN  # a nook at the west edge, nearly seen
    occupancy = OccupancyMap(grid=cells, origin_xy=(0.0, 0.0), resolution_m=0.1)
    planner.graph = planner._graph().model_copy(update={"occupancy": occupancy})
    nook, open_edge, beside = (2.1, 10.0), (29.9, 10.0), (29.9, 2.0)
    assert planner._informative((nook, open_edge, beside)) == (open_edge, beside)
    assert planner._informative((nook,)) == (nook,)  # a single frontier is kept whatever it shows


def test_unlisted_categories_do_not_rank_rooms() -> None:
    assert is_furniture("fridge") and not is_furniture("tennis_racket")


def test_a_room_whose_last_explores_revealed_nothing_yields_to_opening() -> None:
    from more_agent.planners.base import EpisodeContext

    kitchen = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)  # untouched by other tests
    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.observe()
    planner.opened_in_a_row = OPENS_BEFORE_EXPLORING  # containers of the room had their turn
    lit = planner.literals[0]
    step = planner._search(lit, None)
    assert step.action.name == "explore" and step.frontiers
    planner.fruitless[step.region] = FRUITLESS_EXPLORES - 1
    assert planner._search(lit, None).action.name == "explore"  # one explore without news is not enough
    planner.fruitless[step.region] = FRUITLESS_EXPLORES  # its last explores showed nothing new
    assert planner._search(lit, None).action.name == "go_to_and_open"


def test_a_scope_the_goal_moves_binds_to_no_scene_fixture() -> None:
    inst = instantiate("loading_the_car", None, 1, start="task-room", distractors=False)
    goal = task_goal(inst, GoalChecker(inst))
    assert "container.n.01_1" in goal.moved and "car.n.01_1" not in goal.moved  # a container goes into the car
    container = goal.categories["container.n.01_1"]
    assert "car" not in container and "shopping_cart" not in container and "bucket" in container
    assert goal.categories["car.n.01_1"] == {"car"}
    assert can_hold_things("car") and can_hold_things("bottom_cabinet") and not can_hold_things("laptop")


def test_an_object_that_cannot_be_picked_up_is_dropped_at_once(kitchen: TaskInstance) -> None:
    from more_agent.planners.base import EpisodeContext

    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.observe()
    scope = next(s for s in sorted(planner.goal.moved) if planner._label(s) is not None)
    label = planner.bound[scope]
    planner._step = _Step(HighLevelAction("go_to_and_grasp", ("kitchen_0", label)), target=label)
    hand = ActionResult(ok=False, reason=FailureReason.HAND_FULL, feedback="hand is full")
    planner._failed(planner._step.action, planner._step, hand)
    assert planner.bound[scope] == label  # one failure of another kind: tried again
    refused = ActionResult(ok=False, reason=FailureReason.NOT_GRASPABLE, feedback=f"{label} cannot be picked up")
    planner._failed(planner._step.action, planner._step, refused)  # as if it were furniture
    assert scope not in planner.bound and label in planner.dropped and planner._label(scope) != label


def test_what_lies_on_the_ground_is_on_its_floor_and_goes_on_furniture_to_be_off_it(kitchen: TaskInstance) -> None:
    from more_agent.planners.base import EpisodeContext

    planner = GroundedPlanner()
    planner.reset(EpisodeContext(instance=kitchen, goals=BlindGoals(kitchen)))
    planner.observe()
    fridge = planner.seen["fridge A"]
    assert fridge.bbox.min[2] <= GROUND_M and _on_floor(planner.relation["fridge A"])  # it stands on the floor
    scope = next(s for s in sorted(planner.goal.moved) if planner._label(s) is not None)
    item = planner.bound[scope]
    assert not _on_floor(planner.relation[item])  # on a counter or inside a cabinet
    floor = next(iter(planner.goal.floor_rooms))
    assert planner._put_down(item).action.arguments[1] == FLOOR
    planner.literals = [Literal("ontop", (scope, floor), negated=True)]
    planner.relation[item] = ("ontop", f"{FLOOR} kitchen")
    assert planner._holds(planner.literals[0]) is False
    support = planner._put_down(item)
    assert support.target is not None and support.target != item and is_furniture(planner.seen[support.target].category)
