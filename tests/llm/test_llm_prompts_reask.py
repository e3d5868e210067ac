"""Prompt rendering and the bounded re-ask loop (against the fake server)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import pytest

from more_agent.errors import UserError
from more_agent.llm import (
    InvalidAnswer,
    LLMConfig,
    PlanAnswer,
    ask_validated,
    filter_messages,
    history_text,
    make_client,
    parse_plan_answer,
    plan_messages,
    render_prompt,
    room_messages,
)
from more_agent.llm.prompts import PROMPT_NAMES, check_history, prompt_fields
from more_agent.skills import SKILLS
from tests.fakes.openai_server import FakeOpenAIServer


@dataclass
class Action:
    name: str
    arguments: list[str] = field(default_factory=list)
    ok: bool = True
    feedback: str = ""


def test_every_template_renders_with_its_fields() -> None:
    for name in PROMPT_NAMES:
        fields = {f: f"<{f}>" for f in prompt_fields(name)}
        messages = render_prompt(name, **fields)
        assert [m["role"] for m in messages] == ["system", "user"]
        text = "".join(m["content"] for m in messages)
        assert all(f"<{f}>" in text for f in fields) and "$" not in text


def test_render_rejects_missing_and_unknown_fields() -> None:
    with pytest.raises(ValueError, match="needs fields"):
        render_prompt("filter", task="t")
    with pytest.raises(ValueError, match="has no fields"):
        render_prompt("filter", task="t", scene="s", robot="r")
    with pytest.raises(ValueError, match="unknown prompt"):
        render_prompt("planning")


def test_history_shows_last_five_and_all_failed() -> None:
    actions = [Action("explore", ["kitchen_0"], ok=(i != 1), feedback="no frontier") for i in range(8)]
    lines = history_text(actions).splitlines()
    assert [line.split(".")[0] for line in lines] == ["2", "4", "5", "6", "7", "8"]
    assert lines[0] == "2. explore(kitchen_0) -> failed: no frontier" and lines[-1].endswith("succeeded: no frontier")
    assert history_text([]) == "none"


def test_paper_history_forgets_old_successes_and_lasting_keeps_them() -> None:
    placed = Action("go_to_and_place_inside", ["kitchen_0", "toolbox A"], ok=True, feedback="placed hammer A inside toolbox A")
    actions = [placed] + [Action("explore", ["kitchen_0"], ok=True, feedback="explored kitchen_0") for _ in range(7)]
    paper = history_text(actions).splitlines()
    assert paper == history_text(actions, "paper").splitlines()  # the paper's history is the default
    assert [line.split(".")[0] for line in paper] == ["4", "5", "6", "7", "8"]
    lines = history_text(actions, "lasting").splitlines()
    assert lines[0] == "1. go_to_and_place_inside(kitchen_0, toolbox A) -> succeeded: placed hammer A inside toolbox A"
    assert [line.split(".")[0] for line in lines] == ["1", "4", "5", "6", "7", "8"]  # explores: the last five only


def test_history_modes_are_checked_with_the_closest_name() -> None:
    assert check_history("lasting") == "lasting"
    with pytest.raises(UserError, match=r"unknown history 'papr'; closest: paper; use --history with one of: paper, lasting"):
        check_history("papr")


def test_message_builders_fill_the_paper_fields() -> None:
    scene = "kitchen_0:\n- fridge_a [closed]\n- apple_a"
    planning = plan_messages(
        task="Put the apple in the fridge.", scene=scene, robot_room="kitchen_0", held_object=None,
        history=[Action("go_to_and_open", ["kitchen_0", "fridge_a"], ok=False, feedback="hand is full")], feedback="hand is full",
    )
    system, user = planning[0]["content"], planning[1]["content"]
    assert all(s.signature in system for s in SKILLS)
    assert scene in user and "holding nothing" in user and "1. go_to_and_open(kitchen_0, fridge_a) -> failed: hand is full" in user
    assert "Last feedback: hand is full" in user
    assert scene in filter_messages("Put the apple in the fridge.", scene)[1]["content"]
    assert "fridge, oven" in room_messages(["fridge", "oven"], ["kitchen", "bathroom"])[1]["content"]


def _reply(skill: str, *args: str) -> str:
    return json.dumps({"reasoning": "r", "skill": skill, "arguments": list(args)})


def _validate(answer: object) -> object:
    return parse_plan_answer(answer, SKILLS, ["kitchen_0"], ["apple_a", "fridge_a"])  # type: ignore[arg-type]


def test_reask_feeds_back_the_reason_then_succeeds(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push("no idea", _reply("go_to_and_grasp", "kitchen_0", "aple_a"), _reply("go_to_and_grasp", "kitchen_0", "apple_a"))
    client = make_client("openai:gpt-4o", llm_config)
    messages = [{"role": "user", "content": "next?"}]
    out = ask_validated(client, messages, PlanAnswer, _validate, purpose="plan")  # type: ignore[arg-type]
    assert out.value.call == "go_to_and_grasp(kitchen_0, apple_a)"  # type: ignore[attr-defined]
    assert len(out.completions) == 3 and len(fake_openai.requests) == 3
    last = fake_openai.requests[-1].body["messages"]
    assert len(last) == 5 and last[1] == {"role": "assistant", "content": "no idea"}
    assert "no JSON object" in last[2]["content"] and "unknown object 'aple_a'" in last[4]["content"]
    assert "apple_a" in last[4]["content"]


def test_reask_gives_up_with_invalid_answer(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(*[_reply("go_to_and_grasp", "kitchen_0", "banana_a")] * 3)
    client = make_client("openai:gpt-4o", llm_config)
    with pytest.raises(InvalidAnswer, match="banana_a") as info:
        ask_validated(client, [{"role": "user", "content": "next?"}], PlanAnswer, _validate, max_reasks=2)  # type: ignore[list-item]
    assert len(info.value.completions) == 3 and client.usage.calls == 3
