"""Limits on what a model sends back: oversize answers, overlong names, clipped echoes and errors."""

from __future__ import annotations

import json

import pytest

from more_agent.llm import (
    ChatMessage,
    InvalidAnswer,
    LLMBadRequest,
    LLMConfig,
    PlanAnswer,
    ask_validated,
    make_client,
    parse_filter_answer,
    parse_plan_answer,
)
from more_agent.llm.errors import OversizeAnswer
from more_agent.llm.limits import (
    MAX_ANSWER_CHARS,
    MAX_ECHO_CHARS,
    MAX_ERROR_CHARS,
    MAX_NAME_CHARS,
    MAX_REASONING_CHARS,
    clip,
)
from more_agent.skills import SKILLS
from tests.fakes.openai_server import FakeOpenAIServer, Reply, Status

MESSAGES = [ChatMessage(role="user", content="plan")]
DONE = json.dumps({"reasoning": "ok", "skill": "done", "arguments": []})
HUGE = '{"reasoning": "' + "x" * 5_000_000 + '", "skill": "done", "arguments": []}'


def _roomy(config: LLMConfig) -> LLMConfig:
    """``config`` with a deadline a loaded CI worker meets while moving megabytes (these tests are not about time)."""
    return config.model_copy(update={"timeout_s": 30.0})


def _validate(answer: object) -> object:
    return parse_plan_answer(answer, SKILLS, ["kitchen_0"], ["apple_a"])  # type: ignore[arg-type]


def test_clip_is_bounded_and_idempotent() -> None:
    assert clip("short", 10) == "short"
    cut = clip("y" * 1000, 10)
    assert cut.startswith("y" * 10) and "990 more characters cut" in cut and len(cut) < 50
    assert clip(cut, 10) == cut


def test_oversize_answer_is_invalid_stored_truncated_and_reasked(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    fake_openai.push(Reply(HUGE), Reply(DONE))
    llm_config = _roomy(llm_config)
    client = make_client("openai:m", llm_config)
    out = ask_validated(client, MESSAGES, PlanAnswer, _validate, purpose="plan")
    assert out.value.skill == "done" and len(out.completions) == 2
    assert len(out.completions[0].text) < MAX_ANSWER_CHARS + 100
    reask = fake_openai.requests[1].body["messages"]
    assert "over the limit" in reask[-1]["content"]
    assert len(json.dumps(reask)) < MAX_ECHO_CHARS + 2_000  # the 5 MB answer is not echoed back
    assert llm_config.cache_path.stat().st_size < 10 * MAX_ANSWER_CHARS + 200_000
    # A cache hit of the clipped answer is still rejected, never parsed from its first 16 kB.
    with pytest.raises(OversizeAnswer):
        make_client("openai:m", llm_config).complete(MESSAGES, schema=PlanAnswer, purpose="plan")


def test_overlong_names_are_rejected_without_echo() -> None:
    long_name = "n" * 5_000
    with pytest.raises(InvalidAnswer) as e:
        _validate({"reasoning": "", "skill": "navigate", "arguments": ["kitchen_0", long_name]})
    assert f"limit of {MAX_NAME_CHARS}" in e.value.reason and len(e.value.reason) < 200
    result = parse_filter_answer({"rooms": [{"room": "r" * 5_000, "objects": [long_name]}]}, {"kitchen_0": ["apple_a"]})
    assert result.rooms == {} and all(len(n) < MAX_NAME_CHARS + 50 for n in result.unknown_rooms + result.unknown_objects)


def test_reasoning_is_clipped() -> None:
    planned = _validate({"reasoning": "r" * 50_000, "skill": "done", "arguments": []})
    assert MAX_REASONING_CHARS <= len(planned.reasoning) < MAX_REASONING_CHARS + 100  # type: ignore[attr-defined]


def test_server_error_text_is_clipped(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(404, "no such model " + "z" * 1_000_000))
    with pytest.raises(LLMBadRequest) as e:
        make_client("openai:m", _roomy(llm_config)).complete(MESSAGES)
    assert len(str(e.value)) < MAX_ERROR_CHARS + 100
