"""Response cache: hits, bypass, replay, attempt numbers, secrets, concurrent processes."""

from __future__ import annotations

import multiprocessing
from pathlib import Path

import pytest

from more_agent.llm import CacheMode, ChatMessage, LLMConfig, ReplayMiss, ResponseCache, RoomLabelAnswer, make_client
from more_agent.llm.cache import CachedAnswer
from more_agent.llm.concurrency import SlotContext, set_llm_limiter
from tests.fakes.openai_server import FakeOpenAIServer, Reply

MESSAGES = [ChatMessage(role="user", content="objects: bed, wardrobe")]


def test_repeated_call_is_a_cache_hit(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(Reply('{"room": "bedroom"}', prompt_tokens=300, completion_tokens=10))
    client = make_client("openai:gpt-4o", llm_config)
    first = client.complete(MESSAGES, schema=RoomLabelAnswer)
    second = make_client("openai:gpt-4o", llm_config).complete(MESSAGES, schema=RoomLabelAnswer)
    assert len(fake_openai.requests) == 1
    assert second.cached and not first.cached
    assert second.parsed == first.parsed and second.usage == first.usage
    assert second.cost_usd == 0.0 and second.cost_known and second.attempts == 0


def test_key_covers_attempt_schema_model_and_temperature(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push(*['{"room": "bedroom"}'] * 5)
    client = make_client("openai:gpt-4o", llm_config)
    client.complete(MESSAGES)
    client.complete(MESSAGES, attempt=1)
    client.complete(MESSAGES, schema=RoomLabelAnswer)
    make_client("openai:gpt-4o-mini", llm_config).complete(MESSAGES)
    make_client("openai:gpt-4o", llm_config.model_copy(update={"temperature": 0.7})).complete(MESSAGES)
    assert len(fake_openai.requests) == 5
    client.complete(MESSAGES, attempt=1)
    assert len(fake_openai.requests) == 5 and client.usage.cache_hits == 1


@pytest.mark.parametrize("mode", [CacheMode.OFF, CacheMode.REFRESH])
def test_bypass_asks_the_server_every_time(fake_openai: FakeOpenAIServer, llm_config: LLMConfig, mode: CacheMode) -> None:
    fake_openai.push("old", "new")
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": mode}))
    assert [client.complete(MESSAGES).text for _ in range(2)] == ["old", "new"]
    assert len(fake_openai.requests) == 2
    stored = ResponseCache(llm_config.cache_path)
    assert len(stored) == (1 if mode is CacheMode.REFRESH else 0)


def test_replay_hits_offline_and_fails_clearly_on_a_miss(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    fake_openai.push('{"room": "bedroom"}')
    make_client("openai:gpt-4o", llm_config).complete(MESSAGES, schema=RoomLabelAnswer)
    # Replay needs neither the server nor a key: OpenAI's own endpoint, no key.
    replay_config = LLMConfig(cache_mode=CacheMode.REPLAY, cache_path=llm_config.cache_path)
    replay = make_client("openai:gpt-4o", replay_config)
    assert replay.complete(MESSAGES, schema=RoomLabelAnswer).parsed == {"room": "bedroom"}
    other = [ChatMessage(role="user", content="objects: toilet")]
    with pytest.raises(ReplayMiss, match="replay: no cached answer for 'room'") as info:
        replay.complete(other, schema=RoomLabelAnswer, purpose="room")
    assert info.value.model == "gpt-4o"
    assert len(fake_openai.requests) == 1


def test_api_key_never_reaches_the_cache_file(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push('{"room": "bedroom"}', "text")
    client = make_client("openai:gpt-4o", llm_config)
    client.complete(MESSAGES, schema=RoomLabelAnswer)
    client.complete([ChatMessage(role="user", content="hi")])
    key = llm_config.api_key_value()
    assert key and fake_openai.requests[0].headers["authorization"] == f"Bearer {key}"
    files = list(llm_config.cache_path.parent.glob(llm_config.cache_path.name + "*"))
    assert llm_config.cache_path in files
    for f in files:
        assert key.encode() not in f.read_bytes()
    assert key not in repr(llm_config) + repr(client.backend) + str(llm_config.model_dump())


def _write_many(path: Path, worker: int) -> None:
    cache = ResponseCache(path)
    for i in range(40):
        cache.put(f"{worker}-{i}", request={"i": i}, purpose="test", answer=CachedAnswer(f"t{i}", "m", 1, 1))


def test_parallel_processes_share_the_cache(tmp_path: Path) -> None:
    path = tmp_path / "shared.sqlite"
    ResponseCache(path).get("warm-up")
    ctx = multiprocessing.get_context("fork")
    procs = [ctx.Process(target=_write_many, args=(path, w)) for w in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=30)
    assert [p.exitcode for p in procs] == [0] * 4
    cache = ResponseCache(path)
    assert len(cache) == 160 and cache.get("3-39") == CachedAnswer("t39", "m", 1, 1)


class _CountingLimiter(SlotContext):
    """A limiter that counts the slots taken, to see which calls go through it."""

    def __init__(self) -> None:
        self.acquired = 0
        self.held = 0

    def acquire(self) -> None:
        self.acquired += 1
        self.held += 1

    def release(self) -> None:
        self.held -= 1


def test_server_calls_hold_an_evaluation_slot_and_cache_hits_do_not(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    fake_openai.push(Reply('{"room": "kitchen"}'))
    limiter = _CountingLimiter()
    set_llm_limiter(limiter)
    try:
        make_client("openai:gpt-4o", llm_config).complete(MESSAGES, schema=RoomLabelAnswer)
        make_client("openai:gpt-4o", llm_config).complete(MESSAGES, schema=RoomLabelAnswer)
    finally:
        set_llm_limiter(None)
    assert (limiter.acquired, limiter.held) == (1, 0)
