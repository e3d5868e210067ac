"""The skill table is the one vocabulary: the env's action types, the world's manipulations, the
planners' subpolicies and the prompts all follow it."""

from __future__ import annotations

import pytest

from more_agent.llm.parsing import parse_plan_answer
from more_agent.llm.prompts import LASTING_SKILLS, plan_messages, skill_api_text
from more_agent.planners.oracle import world_action
from more_agent.planners.policies import SUBPOLICIES
from more_agent.sim.actions import MANIPULATIONS
from more_agent.sim.env import ACTION_TYPES, MOTIONS
from more_agent.skills import MANIPULATION_VERBS, SKILLS, skill_named


def test_every_subpolicy_and_world_action_of_the_table_has_a_binding() -> None:
    assert {s.subpolicy for s in SKILLS} == set(SUBPOLICIES)
    assert tuple(MANIPULATIONS) == MANIPULATION_VERBS == ("open", "close", "grasp", "place_inside", "place_ontop")
    assert ACTION_TYPES == MOTIONS + tuple(s.world_action for s in SKILLS if s.world_action)
    assert len(set(ACTION_TYPES)) == len(ACTION_TYPES)


def test_prompts_list_the_table_for_the_llm_and_without_arguments_for_the_vlm() -> None:
    system = plan_messages(task="t", scene="s", robot_room="kitchen_0", held_object=None, history=[], feedback="")
    text = " ".join(str(m["content"]) for m in system)
    assert all(f"- {s.signature}: {s.description}" in text for s in SKILLS)
    vlm = skill_api_text(SKILLS, vlm=True).splitlines()
    assert vlm[0] == "- explore(): explore the closest unexplored area (frontier)" and len(vlm) == len(SKILLS)
    assert LASTING_SKILLS == {s.name for s in SKILLS if s.world_action in MANIPULATION_VERBS}


def test_the_parser_checks_arity_against_the_table() -> None:
    action = parse_plan_answer({"reasoning": "", "skill": "go_to_and_grasp", "arguments": ["kitchen_0", "apple_a"]},
                               SKILLS, ["kitchen_0"], ["apple_a"])
    assert action.skill == "go_to_and_grasp" and action.object == "apple_a"


def test_the_oracle_runs_world_actions_and_refuses_map_only_skills() -> None:
    assert [world_action(n) for n in ("navigate_to", "go_to_and_place_inside", "done")] == ["navigate_to", "place_inside", "done"]
    with pytest.raises(ValueError, match="explore"):
        world_action("explore")
    with pytest.raises(ValueError, match="unknown skill"):
        skill_named("fly")
