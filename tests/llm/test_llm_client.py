"""The OpenAI-compatible client against the fake server: answers, usage, cost, retries, errors, fallback."""

from __future__ import annotations

import time

import pytest

from more_agent.llm import (
    ChatMessage,
    LLMAuthError,
    LLMBadRequest,
    LLMConfig,
    LLMConnectionError,
    LLMRateLimited,
    LLMServerError,
    LLMTimeout,
    RoomLabelAnswer,
    StructuredOutput,
    Unparseable,
    make_client,
)
from more_agent.llm.grammar import bounded_schema
from tests.fakes.openai_server import Close, Delay, FakeOpenAIServer, Raw, Reply, Status

MESSAGES = [ChatMessage(role="system", content="label rooms"), ChatMessage(role="user", content="fridge, oven, sink")]


def test_answer_with_usage_cost_and_schema(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Reply('{"room": "kitchen"}', prompt_tokens=1000, completion_tokens=200))
    client = make_client("openai:gpt-4o", llm_config)
    out = client.complete(MESSAGES, schema=RoomLabelAnswer, purpose="room")
    assert out.parsed == {"room": "kitchen"}
    assert (out.usage.prompt_tokens, out.usage.completion_tokens) == (1000, 200)
    assert out.cost_usd == pytest.approx((1000 * 2.50 + 200 * 10.00) / 1e6)
    assert out.cost_known and not out.cached and out.attempts == 1 and out.purpose == "room"
    (req,) = fake_openai.requests
    assert req.body["model"] == "gpt-4o" and req.body["messages"] == MESSAGES and req.body["temperature"] == 0.0
    rf = req.body["response_format"]
    assert rf["type"] == "json_schema" and rf["json_schema"]["name"] == "RoomLabelAnswer"
    assert rf["json_schema"]["schema"]["required"] == ["room"]
    assert req.headers["authorization"] == f"Bearer {llm_config.api_key_value()}"
    assert client.usage.totals() == {
        "calls": 1, "prompt_tokens": 1000, "completion_tokens": 200, "cost_usd": out.cost_usd, "cache_hits": 0,
        "images": 0, "image_bytes": 0, "image_tokens": 0, "reasoning_tokens": 0,
    }


def test_unknown_model_costs_zero_and_is_flagged(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push("plain text")
    client = make_client("openai:my-local-llama", llm_config)
    out = client.complete(MESSAGES)
    assert out.text == "plain text" and out.parsed is None
    assert out.cost_usd == 0.0 and not out.cost_known
    assert client.usage.unpriced_models == {"my-local-llama"}
    assert "response_format" not in fake_openai.requests[0].body


def test_json_in_prose_and_fences_is_parsed(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push('Sure!\n```json\n{"room": "bathroom"}\n```\nHope that helps.', 'It is {"room": "garage"} I think')
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": "off"}))
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "bathroom"}
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "garage"}


def test_malformed_answer_raises_unparseable_but_counts(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Reply("I believe this is a kitchen", prompt_tokens=50, completion_tokens=5))
    client = make_client("openai:gpt-4o", llm_config)
    with pytest.raises(Unparseable) as info:
        client.complete(MESSAGES, schema=RoomLabelAnswer, purpose="room")
    assert info.value.completion.text == "I believe this is a kitchen"
    assert client.usage.calls == 1 and client.usage.prompt_tokens == 50


def test_timeout_is_typed_after_bounded_retries(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(*[Delay(5.0)] * 3)
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"timeout_s": 0.2}))
    start = time.monotonic()
    with pytest.raises(LLMTimeout) as info:
        client.complete(MESSAGES)
    assert info.value.attempts == 3 and len(fake_openai.requests) == 3
    assert time.monotonic() - start < 3.0
    assert client.usage.calls == 0


def test_rate_limit_then_success_honours_retry_after(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(429, "slow down", retry_after=0.3), '{"room": "kitchen"}')
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"backoff_max_s": 1.0}))
    start = time.monotonic()
    out = client.complete(MESSAGES, schema=RoomLabelAnswer)
    assert time.monotonic() - start >= 0.3
    assert out.parsed == {"room": "kitchen"} and out.attempts == 2 and len(fake_openai.requests) == 2


def test_rate_limit_on_every_attempt(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(*[Status(429, retry_after=0)] * 3)
    with pytest.raises(LLMRateLimited) as info:
        make_client("openai:gpt-4o", llm_config).complete(MESSAGES)
    assert info.value.status_code == 429 and info.value.attempts == 3


def test_server_errors_are_retried(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(500), Status(503), "ok")
    assert make_client("openai:gpt-4o", llm_config).complete(MESSAGES).text == "ok"
    fake_openai.push(*[Status(502)] * 3)
    with pytest.raises(LLMServerError) as info:
        make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": "off"})).complete(MESSAGES)
    assert info.value.status_code == 502 and len(fake_openai.requests) == 6


def test_garbage_body_is_a_server_error_and_retried(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Raw(b"<html>bad gateway</html>"), "ok", *[Raw(b"<html>bad gateway</html>")] * 3)
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": "off"}))
    assert client.complete(MESSAGES).attempts == 2
    with pytest.raises(LLMServerError, match="not a chat completion") as info:
        client.complete(MESSAGES)
    assert info.value.attempts == 3


def test_bad_request_and_auth_are_not_retried(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(400, "context too long"), Status(401, "bad key"))
    client = make_client("openai:gpt-4o", llm_config)
    with pytest.raises(LLMBadRequest, match="context too long"):
        client.complete(MESSAGES)
    with pytest.raises(LLMAuthError):
        client.complete(MESSAGES)
    assert len(fake_openai.requests) == 2


def test_dropped_connection_is_a_connection_error(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(*[Close()] * 3)
    with pytest.raises(LLMConnectionError) as info:
        make_client("openai:gpt-4o", llm_config).complete(MESSAGES)
    assert info.value.attempts == 3 and len(fake_openai.requests) == 3


def test_server_gone_is_a_connection_error(llm_config: LLMConfig) -> None:
    with FakeOpenAIServer() as gone:
        url = gone.base_url
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"base_url": url}))
    with pytest.raises(LLMConnectionError, match="cannot reach"):
        client.complete(MESSAGES)


def test_rejected_response_format_falls_back_to_text(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(400, "response_format is not supported"), Status(400, "still not"),
                     'Answer: {"room": "kitchen"}', '{"room": "den"}')
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": "off"}))
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "kitchen"}
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "den"}
    sent = [r.body.get("response_format", {}).get("type") for r in fake_openai.requests]
    assert sent == ["json_schema", "json_object", None, None]


@pytest.mark.parametrize(
    "refusal",
    [
        Status(422, "Input should be 'text' or 'json_object'"),
        # llama-cpp-python's server answers an invalid request body with 500; its error names the field
        Status(500, "1 validation error: ('body', 'response_format', 'type') Input should be 'text' or 'json_object'"),
    ],
)
def test_refused_json_schema_is_sent_as_json_object_with_schema(
    refusal: Status, fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    fake_openai.push(refusal, '{"room": "kitchen"}', '{"room": "den"}')
    client = make_client("openai:local", llm_config.model_copy(update={"cache_mode": "off"}))
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "kitchen"}
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "den"}
    formats = [r.body["response_format"] for r in fake_openai.requests]
    assert [f["type"] for f in formats] == ["json_schema", "json_object", "json_object"]
    assert formats[1]["schema"] == bounded_schema(formats[0]["json_schema"]["schema"])  # with the grammar's bounds
    assert formats[1]["schema"]["required"] == ["room"] and formats[1]["schema"]["properties"]["room"]["maxLength"] > 0


def test_server_error_not_about_response_format_is_retried_with_it(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    fake_openai.push(Status(500, "out of memory"), '{"room": "kitchen"}')
    client = make_client("openai:local", llm_config.model_copy(update={"cache_mode": "off"}))
    assert client.complete(MESSAGES, schema=RoomLabelAnswer).attempts == 2
    assert [r.body["response_format"]["type"] for r in fake_openai.requests] == ["json_schema", "json_schema"]


def test_structured_output_always_and_never(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Status(400, "response_format is not supported"), '{"room": "den"}')
    always = make_client("openai:gpt-4o", llm_config.model_copy(update={"structured_output": StructuredOutput.ALWAYS}))
    with pytest.raises(LLMBadRequest):
        always.complete(MESSAGES, schema=RoomLabelAnswer)
    never = make_client("openai:gpt-4o", llm_config.model_copy(update={"structured_output": StructuredOutput.NEVER}))
    assert never.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "den"}
    assert "response_format" not in fake_openai.requests[-1].body


class _CountingLimiter:
    """A limiter that counts the requests it let through."""

    def __init__(self) -> None:
        self.entered = 0

    def acquire(self) -> None:
        self.entered += 1

    def release(self) -> None:
        pass

    def __enter__(self) -> _CountingLimiter:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def test_the_client_holds_the_limiter_it_was_built_with_around_requests_only(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    from more_agent.llm.concurrency import set_llm_limiter

    installed = _CountingLimiter()
    set_llm_limiter(installed)  # what the harness does in each worker
    try:
        client = make_client("openai:gpt-4o", llm_config)
    finally:
        set_llm_limiter(None)
    fake_openai.push('{"room": "kitchen"}')
    client.complete(MESSAGES)
    client.complete(MESSAGES)  # answered from the cache: no slot taken
    assert client.limiter is installed and installed.entered == 1
