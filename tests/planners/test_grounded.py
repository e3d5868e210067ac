"""The grounded planner: goal knowledge without world state, solving a kitchen task through the scene graph."""

from __future__ import annotations

from pathlib import Path

import pytest

from more_agent.eval.episode import reset_planner, run_episode
from more_agent.planners.base import HighLevelAction, default_planner, make_planner
from more_agent.planners.grounded import (
    FLOOR,
    FRUITLESS_EXPLORES,
    GROUND_M,
    OPENS_BEFORE_EXPLORING,
    GroundedPlanner,
    _on_floor,
    _Step,
    far_frontiers,
)
from more_agent.planners.room_types import is_furniture, likely_room_type
from more_agent.records import EpisodeSpec, FailureReason
from more_agent.robot import ActionResult
from more_agent.scene_graph import RegionNode
from more_agent.sim.catalog import can_hold_things
from more_agent.sim.goals import GoalChecker, GoalStatus, Literal
from more_agent.sim.instantiate import TaskInstance, instantiate, instantiate_in_scene
from more_agent.sim.scene import load_scene
from more_agent.sim.task_goal import intended_goal, task_goal
from more_agent.sim.world import World

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


class BlindGoals(GoalChecker):
    """The real goal checker, except that checking the goal (privileged) fails the test."""

    def check(self, world: World | None = None) -> GoalStatus:
        raise AssertionError("the grounded planner checked the goal")


def fresh_kitchen() -> TaskInstance:
    """The kitchen task in a world no other test has acted in."""
    return instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)


def planner_in(kitchen: TaskInstance) -> GroundedPlanner:
    """A grounded planner reset in ``kitchen`` (the goal checker refuses to be asked) after its first observation."""
    planner = GroundedPlanner()
    reset_planner(planner, kitchen, BlindGoals(kitchen))
    planner.observe()
    return planner


@pytest.fixture(scope="module")
def kitchen() -> TaskInstance:
    return fresh_kitchen()


def test_task_goal_is_over_scopes_with_the_labels_the_description_names(kitchen: TaskInstance) -> None:
    goal = task_goal(kitchen, GoalChecker(kitchen))
    world_names = set(kitchen.world.objects)
    assert goal.options and all(not set(lit.args) & world_names for opt in goal.options for lit in opt)
    assert goal.named == {"electric_refrigerator.n.01_1": "fridge A", "cabinet.n.01_1": "bottom_cabinet A"}
    assert "fridge" in goal.categories["electric_refrigerator.n.01_1"]
    assert "egg.n.02_1" not in goal.named  # the description says "dairy", not which instance


def test_a_forall_whose_body_names_one_scope_is_read_over_its_variable() -> None:
    """recycling_office_papers quantifies over every legal document but names legal_document.n.01_1 in
    the body: bddl checks one document no reader can tell apart, the reader puts all of them in the bin."""
    typo = [["forall", ["?x.n.01", "-", "x.n.01"], ["inside", "?x.n.01_1", "?bin.n.01_1"]]]
    assert intended_goal(typo) == [["forall", ["?x.n.01", "-", "x.n.01"], ["inside", "?x.n.01", "?bin.n.01_1"]]]
    meant = [["forall", ["?x.n.01", "-", "x.n.01"], ["ontop", "?x.n.01", "?table.n.01_1"]], ["not", ["open", "?fridge.n.01_1"]]]
    assert intended_goal(meant) == meant
    papers = instantiate("recycling_office_papers", None, 1, start="task-room", distractors=False)
    goal = task_goal(papers, GoalChecker(papers))
    documents = {lit.args[0] for opt in goal.options for lit in opt}
    assert documents == {"legal_document.n.01_1", "legal_document.n.01_2", "legal_document.n.01_3"}


def test_grounded_solves_the_kitchen_task_without_checking_the_goal(kitchen: TaskInstance) -> None:
    planner = GroundedPlanner()
    reset_planner(planner, kitchen, BlindGoals(kitchen))
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


@pytest.mark.slow
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
    from more_agent.scene_graph import OccupancyMap

    kitchen = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)  # untouched by other tests
    planner = GroundedPlanner()
    reset_planner(planner, kitchen, BlindGoals(kitchen))
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
    planner = planner_in(fresh_kitchen())
    planner.opened_in_a_row = OPENS_BEFORE_EXPLORING  # containers of the room had their turn
    lit = planner.literals[0]
    step = planner._search(lit, None)
    assert step.action.name == "explore" and step.frontiers
    planner.fruitless[step.region] = FRUITLESS_EXPLORES - 1
    assert planner._search(lit, None).action.name == "explore"  # one explore without news is not enough
    planner.fruitless[step.region] = FRUITLESS_EXPLORES  # its last explores showed nothing new
    planner.looked_at.update(planner.seen)  # and its furniture was seen from close by
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
    planner = GroundedPlanner()
    reset_planner(planner, kitchen, BlindGoals(kitchen))
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
    planner = GroundedPlanner()
    reset_planner(planner, kitchen, BlindGoals(kitchen))
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


def test_an_object_resting_on_no_furniture_is_on_the_floor() -> None:
    """A floor literal holds for an object the scene graph shows on nothing: the planner does not pick it
    up to put it down again (cleaning_up_branches_and_twigs: the trash can already stands on the lawn)."""
    planner = planner_in(fresh_kitchen())
    floor = next(iter(planner.goal.floor_rooms))
    planner.bound["bag"] = "paper_bag A"  # stands on the floor; the yogurt is inside it
    planner.bound["yogurt"] = "cup_of_yogurt A"
    assert planner._holds(Literal("ontop", ("bag", floor))) is True
    assert planner._holds(Literal("ontop", ("yogurt", floor))) is False


def test_a_stale_task_room_is_searched_at_its_furniture_before_other_rooms() -> None:
    """Explores clear a store's floor, but items on a far shelf show only from close by: once the room of
    the task's objects yields nothing new, the robot drives to its furniture it has not been near."""
    planner = planner_in(fresh_kitchen())
    assert planner._label("cup__of__yogurt.n.01_1") == "cup_of_yogurt A"  # a task object: its room is a task room
    room = planner.seen["cup_of_yogurt A"].region_id
    planner.opened_in_a_row = OPENS_BEFORE_EXPLORING
    planner.fruitless[room] = FRUITLESS_EXPLORES
    step = planner._search(planner.literals[0], None)
    assert step.action.name == "navigate" and planner.seen[step.target].region_id == room
    planner._step = step
    planner.execute(step.action)
    assert planner._search(planner.literals[0], None).target != step.target  # each piece once


def test_the_room_of_the_tasks_objects_is_explored_before_a_fresh_one() -> None:
    """A task's objects are set out together: the room where some were found is searched on before a
    room not explored yet (buying_groceries left the store for a bathroom with groceries unseen)."""
    planner = planner_in(fresh_kitchen())
    graph = planner._graph()
    room = graph.robot.region_id
    other = RegionNode(id="region_far", centroid=(40.0, 40.0), nav_nodes=[], frontiers=[(40.0, 40.0)])
    planner.graph = graph.model_copy(update={"regions": {**graph.regions, other.id: other}})
    planner.explored[room], planner.fruitless[room] = 5, 1  # explored often, the last one without news
    assert planner._room_to_explore([], planner._task_rooms()) == other.id  # nothing of the task found yet: the fresh room
    assert planner._label("cup__of__yogurt.n.01_1") == "cup_of_yogurt A"
    assert planner._room_to_explore([], planner._task_rooms()) == room


def test_when_only_closing_is_left_the_planner_closes() -> None:
    """Closing waits for the other literals, not for the other closings (putting_dishes_away_after_cleaning:
    every cabinet closed, two of them open, and the planner searched instead of closing)."""
    kitchen = fresh_kitchen()
    for scope in ("electric_refrigerator.n.01_1", "cabinet.n.01_1"):
        kitchen.world.set_open(kitchen.scope[scope], True)
    planner = planner_in(kitchen)
    planner.literals = [Literal("open", ("electric_refrigerator.n.01_1",), True), Literal("open", ("cabinet.n.01_1",), True)]
    assert planner.decide().name == "go_to_and_close"


def test_an_object_that_must_leave_the_floor_is_not_picked_up_to_be_put_down_again() -> None:
    """(not (ontop sod lawn)) is met by the placement elsewhere the goal asks for; putting the sod down
    where the robot stands never meets it (remove_sod looped on grasp and put down)."""
    planner = planner_in(fresh_kitchen())
    floor = next(iter(planner.goal.floor_rooms))
    planner.bound["bag"], planner.bound["counter"] = "paper_bag A", "countertop A"
    planner.literals = [Literal("ontop", ("bag", floor), True), Literal("ontop", ("bag", "counter"))]
    assert planner._act_for(planner.literals[0], None) is None


def with_far_room(planner: GroundedPlanner) -> str:
    """Add an unexplored region far from the kitchen to the planner's graph; its id."""
    graph = planner._graph()
    other = RegionNode(id="region_far", centroid=(40.0, 40.0), nav_nodes=[], frontiers=[(40.0, 40.0)])
    planner.graph = graph.model_copy(update={"regions": {**graph.regions, other.id: other}})
    planner.names[other.id] = "garden_0"
    return other.id


def test_missing_furniture_is_not_looked_for_in_containers() -> None:
    """A breakfast table is in no cabinet: when only furniture is missing the search opens nothing
    (putting_out_condiments seed 1 opened twenty kitchen cabinets for one). The kitchen has no bed."""
    planner = planner_in(fresh_kitchen())
    table = "bed.n.01_1"
    planner.goal.categories[table] = frozenset({"bed"})
    unseen = next(lit.args[0] for lit in planner.literals if planner._label(lit.args[0]) is None)
    assert planner._is_furniture_scope(table) and not planner._is_furniture_scope(unseen)
    item = planner._search(Literal("ontop", (unseen, table)), None)
    assert item.action.name == "go_to_and_open"  # an item may be in the closed cabinets of the room
    step = planner._search(Literal("ontop", ("cup__of__yogurt.n.01_1", table)), None)  # the yogurt is in view
    assert step.action.name == "explore"


def test_task_rooms_are_where_the_items_were_found_and_their_containers_are_opened_before_leaving() -> None:
    """Items put in another room leave the room they were found in a task room: the other items are
    likeliest there (the peanut butter of putting_out_condiments in a kitchen cabinet, after the
    vinegar went to a table three rooms away)."""
    planner = planner_in(fresh_kitchen())
    far = with_far_room(planner)
    assert planner._label("cup__of__yogurt.n.01_1") == "cup_of_yogurt A"
    kitchen_room = planner.seen["cup_of_yogurt A"].region_id
    planner.seen["cup_of_yogurt A"] = planner.seen["cup_of_yogurt A"].model_copy(update={"region_id": far})
    assert planner._task_rooms() == {kitchen_room}  # found there, whatever room it was carried to
    planner.fruitless[kitchen_room] = FRUITLESS_EXPLORES  # the kitchen's explores show nothing new
    planner.looked_at.update(planner.seen)  # and its furniture was seen from close by
    planner.opened_in_a_row = OPENS_BEFORE_EXPLORING  # the room's containers had their turn in a row
    lit = next(lit for lit in planner.literals if planner._label(lit.args[0]) is None)
    step = planner._search(lit, None)
    assert step.action.name == "go_to_and_open" and planner.seen[step.target].region_id == kitchen_room
    planner.looked_into.update(planner.seen)  # every container of the kitchen looked into
    assert planner._search(lit, None).region == far  # now the search moves on


def test_an_item_is_not_picked_up_for_a_floor_whose_room_is_not_found_yet() -> None:
    """"on top of the garden floor" from a house: the planner searches for the garden first; before, it
    picked the bag up, found no garden to put it in, put it down again, and so on for 50 steps."""
    planner = planner_in(fresh_kitchen())
    scope = next(s for s in sorted(planner.goal.moved) if planner._label(s) is not None)
    floor = next(iter(planner.goal.floor_rooms))
    lit = Literal("ontop", (scope, floor))
    planner.goal.floor_rooms[floor] = "garden"
    assert planner._floor_region(floor) is None and planner._act_for(lit, None) is None
    planner.goal.floor_rooms[floor] = None  # any floor will do: the one the robot stands on
    assert planner._act_for(lit, None).action.name == "go_to_and_grasp"
