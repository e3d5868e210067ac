"""The perception mode travels like the description mode: spec, record, run config, resume key, folder name;
records of schema 4 read as ground truth; the failure cause ``misperceived`` needs noisy perception."""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from more_agent.errors import UserError
from more_agent.eval.failure import classify_failure
from more_agent.eval.store import RunConfig, check_same_run, episode_dirname, pending
from more_agent.records import RECORD_SCHEMA_VERSION, ActionRecord, EpisodeRecord, EpisodeSpec, GoalCondition
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.scene import load_scene

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


def test_the_spec_keeps_the_canonical_text_and_refuses_a_bad_one() -> None:
    assert EpisodeSpec(task="t").perception == "gt"
    assert EpisodeSpec(task="t", perception="noisy:depth=0.010,miss=0.2").perception == "noisy"  # defaults dropped
    assert EpisodeSpec(task="t", perception="noisy:miss=0.5").perception == "noisy:miss=0.5"
    with pytest.raises(ValidationError, match="valid keys"):
        EpisodeSpec(task="t", perception="noisy:blur=1")


def test_records_carry_the_mode_and_schema_4_reads_as_ground_truth() -> None:
    spec = EpisodeSpec(task="t", perception="noisy:drift=0")
    assert EpisodeRecord.for_spec(spec).perception == "noisy:drift=0"
    old = EpisodeRecord.model_validate({"schema_version": 4, "task": "t", "scene": "s", "seed": 0, "planner": "more"})
    assert (old.perception, old.misperceived, old.schema_version) == ("gt", {}, RECORD_SCHEMA_VERSION)


def test_resume_key_and_folder_name_tell_the_modes_apart(tmp_path: Path) -> None:
    noisy = EpisodeSpec(task="a", perception="noisy")
    done = [EpisodeRecord.for_spec(EpisodeSpec(task="a", scene="Rs_int"))]
    assert pending([noisy], done) == [noisy] and pending([EpisodeSpec(task="a")], done) == []
    assert (
        episode_dirname("a", None, 0, "grounded", perception="noisy:miss=0.5") == "a__auto__s0__grounded__noisy-miss0.5"
    )
    assert episode_dirname("a", None, 0, "grounded") == "a__auto__s0__grounded"
    run = RunConfig(planner="grounded", tasks=["a"], seeds=[0], episode_fn="m:f")
    with pytest.raises(UserError, match="perception: 'gt' -> 'noisy'"):
        check_same_run(tmp_path, run, run.model_copy(update={"perception": "noisy"}))


@pytest.fixture(scope="module")
def kitchen() -> TaskInstance:
    inst = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)
    inst.labels.assign_all(inst.world)  # as after an episode that saw everything: the causes name objects by label
    return inst


def _record(**fields: object) -> EpisodeRecord:
    unmet = GoalCondition(
        text="(inside canned_food_1 bottom_cabinet_0)", satisfied=False, objects=["canned_food_1", "bottom_cabinet_0"]
    )
    base: dict[str, object] = dict(
        task="t",
        scene="s",
        seed=0,
        planner="grounded",
        goal_conditions=[unmet],
        observed_objects=["bottom_cabinet_0"],
        high_level_steps=50,
        termination="step_limit",
    )
    return EpisodeRecord(**{**base, **fields})


def test_misperceived_names_the_needed_object_perception_hid_or_the_mislabelled_one_acted_on(kitchen: TaskInstance) -> None:
    world, labels = kitchen.world, kitchen.labels
    plain = classify_failure(_record(), world, labels)
    assert plain is not None and plain.cause == "never_observed"  # ground truth: as before
    hidden = classify_failure(_record(misperceived={"canned_food_1": "seen as soup_can C"}), world, labels)
    assert hidden is not None and hidden.cause == "misperceived"
    assert hidden.detail == f"{labels.label('canned_food_1')}: seen as soup_can C"
    grasp = ActionRecord(step=0, name="go_to_and_grasp", arguments=["kitchen_0", "bowl C"], ok=True)
    acted = _record(
        actions=[grasp],
        perception_aliases={"bowl C": "canned_food_1"},
        observed_objects=["canned_food_1", "bottom_cabinet_0"],
    )
    failure = classify_failure(acted, world, labels)
    assert failure is not None and failure.cause == "misperceived" and "acted on bowl C, which is" in failure.detail
    piece = _record(
        actions=[grasp.model_copy(update={"arguments": ["kitchen_0", "canned_food C"]})],
        perception_aliases={"canned_food C": "canned_food_1"},
        observed_objects=["canned_food_1", "bottom_cabinet_0"],
    )
    other = classify_failure(piece, world, labels)
    assert other is not None and other.cause != "misperceived"  # a second piece of the same category is no mislabel
