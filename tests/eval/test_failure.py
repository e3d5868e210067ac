"""Failure causes from an episode's own trace and the world's ground truth, and their counts in the summary."""

from __future__ import annotations

from pathlib import Path

import pytest

from more_agent.eval.failure import cause_counts, classify_failure
from more_agent.eval.report import summary_markdown
from more_agent.records import ActionRecord, EpisodeRecord, FailureReason, GoalCondition
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


@pytest.fixture(scope="module")
def kitchen() -> TaskInstance:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)
    inst.labels.assign_all(inst.world)  # as after an episode that saw everything: the causes name objects by label
    return inst


@pytest.fixture
def world(kitchen: TaskInstance) -> World:
    return kitchen.world


@pytest.fixture
def labels(kitchen: TaskInstance) -> InstanceLabels:
    return kitchen.labels


def _record(**fields: object) -> EpisodeRecord:
    unmet = GoalCondition(text="(inside canned_food_1 bottom_cabinet_0)", satisfied=False,
                          objects=["canned_food_1", "bottom_cabinet_0"])
    base: dict[str, object] = dict(task="t", scene="s", seed=0, planner="grounded", goal_conditions=[unmet],
                                   observed_objects=["canned_food_1", "bottom_cabinet_0"], high_level_steps=3)
    return EpisodeRecord(**{**base, **fields})


def _act(name: str, target: str, ok: bool, feedback: str = "", reason: FailureReason | None = None) -> ActionRecord:
    return ActionRecord(step=0, name=name, arguments=["kitchen_0", target], ok=ok, feedback=feedback, reason=reason)


def test_each_cause_from_the_trace(world: World, labels: InstanceLabels) -> None:
    def cause(record: EpisodeRecord) -> str | None:
        failure = classify_failure(record, world, labels)
        return None if failure is None else failure.cause

    assert cause(_record(success=True, all_goals_met=True, done_called=True)) is None
    assert cause(_record(error="LLM error (LLMTimeout): slow", error_kind="llm")) == "llm_error"
    assert cause(_record(error="ValueError: x", error_kind="crash", traceback="...")) == "other"
    assert cause(_record(all_goals_met=True)) == "done_not_called"
    assert cause(_record(observed_objects=["bottom_cabinet_0"])) == "never_observed"
    assert cause(_record(actions=[_act("go_to_and_place_inside", "bottom_cabinet B", True)])) == "wrong_instance"
    looked_inside = _record(actions=[_act("go_to_and_open", "bottom_cabinet B", True)], done_called=True)
    assert cause(looked_inside) == "done_early"  # opening another cabinet is a search, not the goal's cabinet mistaken
    opens = GoalCondition(text="(open bottom_cabinet_0)", satisfied=False, objects=["bottom_cabinet_0"])
    assert cause(_record(actions=looked_inside.actions, goal_conditions=[opens])) == "wrong_instance"
    other_goal = GoalCondition(text="(open bottom_cabinet_1)", satisfied=True, objects=["bottom_cabinet_1"])
    both = _record(actions=[_act("go_to_and_place_inside", "bottom_cabinet B", True)], done_called=True)
    both.goal_conditions.append(other_goal)
    assert cause(both) == "done_early"  # bottom_cabinet B is a goal object too: not a wrong instance
    placed = _record(actions=[_act("go_to_and_place_inside", "bottom_cabinet B", True)], done_called=True)
    any_of = classify_failure(placed, world, labels, goal_objects={"bottom_cabinet_0", "bottom_cabinet_1"})
    assert any_of is not None and any_of.cause == "done_early"  # another option of the goal uses cabinet B
    unreachable = _act("go_to_and_grasp", "canned_food A", False, "no path", FailureReason.NOT_REACHABLE)
    assert cause(_record(actions=[unreachable])) == "unreachable"
    blocked = _act("go_to_and_grasp", "canned_food A", False, "blocked", FailureReason.PATH_BLOCKED_BY_DOOR)
    assert cause(_record(actions=[blocked])) == "unreachable"
    hand_full = _act("go_to_and_grasp", "canned_food A", False, "hand is full; holding apple A", FailureReason.HAND_FULL)
    assert cause(_record(actions=[hand_full])) == "subpolicy_failure"
    invalid = [ActionRecord(step=i, name="invalid", ok=False, reason=FailureReason.INVALID_ANSWER) for i in range(3)]
    assert cause(_record(actions=invalid)) == "invalid_llm_answers"
    assert cause(_record(done_called=True, termination="done")) == "done_early"
    assert cause(_record(high_level_steps=50, termination="step_limit")) == "step_limit"
    unseen = _record(observed_objects=["bottom_cabinet_0"])
    impossible = classify_failure(unseen, world, labels, satisfiable=False)  # no robot meets it, seen or not
    assert impossible is not None and impossible.cause == "unsatisfiable"
    timed_out = _record(error="LLM error (LLMTimeout): slow", error_kind="llm")
    assert classify_failure(timed_out, world, labels, satisfiable=False).cause == "llm_error"  # type: ignore[union-attr]
    detail = classify_failure(_record(observed_objects=["bottom_cabinet_0"]), world, labels)
    assert detail is not None and detail.detail == "never observed canned_food A"  # labels, as the robot knows them


def test_causes_read_types_not_text(world: World, labels: InstanceLabels) -> None:
    """Feedback and error text that reads like another cause changes nothing: only the typed fields count."""
    worded = _act("go_to_and_grasp", "canned_food A", False, "cannot reach canned_food A: no path on the map",
                  FailureReason.HAND_FULL)
    assert classify_failure(_record(actions=[worded]), world, labels).cause == "subpolicy_failure"  # type: ignore[union-attr]
    named_invalid = [ActionRecord(step=i, name="invalid", ok=False) for i in range(3)]
    assert classify_failure(_record(actions=named_invalid), world, labels).cause != "invalid_llm_answers"  # type: ignore[union-attr]
    ended = classify_failure(_record(high_level_steps=50, termination="step_limit"), world, labels)
    assert ended is not None and ended.detail.startswith("step limit of 50 high-level steps reached; ")
    gave_up = classify_failure(_record(done_called=True, termination="done", gave_up="nothing fits"), world, labels)
    assert gave_up is not None and (gave_up.cause, gave_up.detail) == ("done_early", "nothing fits")


def test_summary_counts_causes_per_system(world: World, labels: InstanceLabels) -> None:
    records = [_record(observed_objects=[]), _record(done_called=True), _record(success=True, all_goals_met=True)]
    records = [r.model_copy(update={"failure": classify_failure(r, world, labels)}) for r in records]
    assert cause_counts(records) == {"never_observed": 1, "done_early": 1}
    md = summary_markdown(records)
    assert "| System | n | failures | never_observed | done_early |\n" in md and "| grounded | 3 | 2 | 1 | 1 |" in md


def test_a_wrong_instance_names_a_needed_one_never_seen_by_its_world_name() -> None:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)
    world, labels = inst.world, InstanceLabels()
    labels.observe(o for o in world.objects.values() if o.name != "bottom_cabinet_0")  # the needed one never seen
    other = labels.label("bottom_cabinet_1")
    assert other.startswith("bottom_cabinet ")
    failure = classify_failure(_record(actions=[_act("go_to_and_place_inside", other, True)]), world, labels)
    assert failure is not None and failure.cause == "wrong_instance"
    assert failure.detail.endswith("the goal needs bottom_cabinet_0 (never observed)")


def test_a_goal_the_world_cannot_meet_is_not_lost_to_what_was_never_seen(world: World, labels: InstanceLabels) -> None:
    """A goal over a predicate the world does not model (``cooked``) is met by no robot: that its object was
    never seen explains nothing (docs/evaluation.md: done_early)."""
    cooked = GoalCondition(text="(cooked canned_food_1)", satisfied=False, objects=["canned_food_1"])
    record = _record(goal_conditions=[cooked], observed_objects=[], done_called=True, termination="done")
    failure = classify_failure(record, world, labels)
    assert failure is not None and failure.cause == "done_early"
    negated = GoalCondition(text="(not (inside canned_food_1 bottom_cabinet_0))", satisfied=False,
                            objects=["canned_food_1", "bottom_cabinet_0"])
    failure = classify_failure(_record(goal_conditions=[negated], observed_objects=[]), world, labels)
    assert failure is not None and failure.cause == "never_observed"  # a modelled predicate, negated
