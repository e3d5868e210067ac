"""Task catalogue: names, task sets, scene matching against bddl's knowledge base, goal descriptions."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

from more_agent.errors import UserError
from more_agent.sim.tasks import (
    compute_suitable_scenes,
    describe_goal,
    is_rearrangement_goal,
    load_task,
    room_matches,
    suitable_scenes,
    task_data,
    task_names,
    task_set,
)

FIXTURES = Path(__file__).parent.parent / "fixtures"


def test_all_bddl_activities_are_tasks() -> None:
    names = task_names()
    assert len(names) == 1016
    assert "putting_shopping_away" in names


def test_unknown_task_names_closest() -> None:
    with pytest.raises(UserError, match="putting_shopping_away"):
        load_task("puting_shoping_away")


def test_load_task_parses_objects_and_goal() -> None:
    d = load_task("putting_shopping_away")
    assert d.objects["sack.n.01"] == ["sack.n.01_1", "sack.n.01_2"]
    assert d.goal_predicates == {"inside"}
    assert d.n_goal_literals == 5
    assert d.room_requirements() == {
        "kitchen": Counter({"floor.n.01": 1, "cabinet.n.01": 1, "electric_refrigerator.n.01": 1})
    }
    assert load_task("putting_shopping_away") is d  # cached


def test_scene_matching_reproduces_bddl_knowledge_base_for_paper_tasks() -> None:
    expected = json.loads((FIXTURES / "tasks_matched_scenes_more_paper.json").read_text())
    assert len(expected) == 55
    for task, scenes in expected.items():
        assert compute_suitable_scenes(load_task(task)) == sorted(scenes), task
        assert suitable_scenes(task) == sorted(scenes), task


def test_room_matching_is_one_to_one() -> None:
    two_cabinets = Counter({"cabinet.n.01": 2})
    assert room_matches({"bottom_cabinet-abc": 1}, two_cabinets) == ["cabinet.n.01"]
    assert room_matches({"bottom_cabinet-abc": 1, "top_cabinet-xyz": 1}, two_cabinets) == []
    assert room_matches({"fridge-a": 3}, two_cabinets) == ["cabinet.n.01"]


def test_task_sets() -> None:
    paper = task_set("more-paper")
    assert len(paper) == 55 and "putting_shopping_away" in paper
    rearrange = task_set("behavior-rearrange")
    assert 150 <= len(rearrange) <= 210
    data = task_data()["tasks"]
    for name in rearrange:
        assert is_rearrangement_goal(load_task(name)) and data[name]["instantiable"], name
    with pytest.raises(UserError, match="more-paper"):
        task_set("more_paper")


def test_package_data_covers_every_task() -> None:
    data = task_data()["tasks"]
    assert set(data) == set(task_names())
    for name, e in data.items():
        assert e["instantiable"] or e["reason"], name  # every failure says why


def test_describe_goal_quantifiers_and_negation() -> None:
    goal = [
        ["inside", "?apple.n.01_1", "?electric_refrigerator.n.01_1"],
        ["forall", ["?plate.n.04", "-", "plate.n.04"], ["ontop", "?plate.n.04", "?table.n.02_1"]],
        ["exists", ["?bowl.n.01", "-", "bowl.n.01"], ["inside", "?pack__of__pasta.n.01_1", "?bowl.n.01"]],
        ["not", ["open", "?electric_refrigerator.n.01_1"]],
        ["forpairs", ["?sack.n.01", "-", "sack.n.01"], ["?doll.n.01", "-", "doll.n.01"], ["inside", "?doll.n.01", "?sack.n.01"]],
    ]
    labels = {"apple.n.01_1": "apple A", "electric_refrigerator.n.01_1": "fridge A", "table.n.02_1": "table A",
              "pack__of__pasta.n.01_1": "pack of pasta A"}
    text = describe_goal(goal, labels.__getitem__)
    assert text == (
        "put apple A inside fridge A; put every plate on top of table A; put pack of pasta A inside a bowl; "
        "close fridge A; put a different doll inside each sack"
    )


def test_a_quantifier_over_a_choice_or_a_shared_object_keeps_its_scope() -> None:
    """stacking_wood's goal puts every log on the table or on some log: each log chooses. Carrying "every log"
    into each branch of the ``or`` read "either every log on the table or every log on log A", another goal
    (and an ``or`` nested in it, as bddl writes it, "or either").
    One sack holding three items is not three sacks; "every" still carries over an ``and``."""
    log = ["?log.n.01", "-", "log.n.01"]
    goal = [
        ["forall", log, ["or", ["ontop", "?log.n.01", "?table.n.02_1"], ["or", ["ontop", "?log.n.01", "?log.n.01_1"]]]],
        ["exists", ["?sack.n.01", "-", "sack.n.01"],
         ["and", ["inside", "?apple.n.01_1", "?sack.n.01"], ["inside", "?banana.n.02_1", "?sack.n.01"]]],
        ["forn", ["2"], log, ["ontop", "?log.n.01", "?table.n.02_1"]],
        ["forall", log, ["and", ["ontop", "?log.n.01", "?table.n.02_1"], ["not", ["open", "?log.n.01"]]]],
    ]
    labels = {"table.n.02_1": "table A", "log.n.01_1": "log A", "apple.n.01_1": "apple A", "banana.n.02_1": "banana A"}
    assert describe_goal(goal, labels.__getitem__).split("; ") == [
        "for every log: either put that log on top of table A or put that log on top of log A",
        "for a sack: put apple A inside that sack and put banana A inside that sack",
        "put exactly 2 log(s) on top of table A",
        "put every log on top of table A and close every log",
    ]
