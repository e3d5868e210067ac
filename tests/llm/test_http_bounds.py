"""One wall-clock deadline per LLM request and a body cap, through a real local HTTP server: a server
that trickles its headers or its body one byte at a time, or floods 200 MB, ends the request within
the timeout with a typed error; usage that cannot be is counted as unknown; the settings that would
reach a header or a record are refused."""

from __future__ import annotations

import sqlite3
import time
from pathlib import Path

import pytest

from more_agent.llm.cache import ResponseCache
from more_agent.llm.client import ChatRequest
from more_agent.llm.config import load_llm_config
from more_agent.llm.errors import CacheLocked, LLMConfigError, LLMResponseTooLarge, LLMTimeout
from more_agent.llm.openai_backend import OpenAIBackend
from tests.fakes.openai_server import FakeOpenAIServer, Huge, Reply, Trickle

REQUEST = ChatRequest(messages=({"role": "user", "content": "hi"},), schema=None, schema_name="", temperature=0.0,
                      max_tokens=16, seed=None)


def _backend(server: FakeOpenAIServer, *, timeout_s: float = 1.0, max_retries: int = 0) -> OpenAIBackend:
    return OpenAIBackend(model="m", base_url=server.base_url, api_key="sk-test-0123456789", timeout_s=timeout_s,
                         max_retries=max_retries, backoff_initial_s=0.0, backoff_max_s=0.0)


@pytest.mark.parametrize("headers", [False, True], ids=["body", "headers"])
def test_a_trickling_server_times_out_within_the_deadline(headers: bool) -> None:
    with FakeOpenAIServer([Trickle(Reply("x" * 200), interval_s=0.1, headers=headers)] * 2) as server:
        backend = _backend(server, timeout_s=1.0, max_retries=1)
        backend._client()  # the SDK import is not part of the request
        start = time.perf_counter()
        with pytest.raises(LLMTimeout, match="whole request") as e:
            backend.generate(REQUEST)
        seconds = time.perf_counter() - start
    assert e.value.retryable and e.value.attempts == 2
    assert 1.9 < seconds < 3.5  # two attempts of one second each, not 200 bytes x 0.1 s


@pytest.mark.parametrize("declare_length", [True, False])
def test_a_body_over_the_cap_is_its_own_error_and_not_retried(declare_length: bool) -> None:
    with FakeOpenAIServer([Huge(200_000_000, declare_length=declare_length)] * 3) as server:
        with pytest.raises(LLMResponseTooLarge, match="over 8388608 bytes") as e:
            _backend(server, timeout_s=30.0, max_retries=2).generate(REQUEST)
        assert len(server.requests) == 1
    assert not e.value.retryable


@pytest.mark.parametrize(
    ("prompt", "completion", "counted"), [(-300_000_000, 20, (0, 20)), (1e300, 7, (0, 7)), (None, None, (0, 0)), (2.5, 3, (0, 3))]
)
def test_usage_that_cannot_be_counts_as_unknown(prompt: object, completion: object, counted: tuple[int, int]) -> None:
    with FakeOpenAIServer([Reply("ok", prompt_tokens=prompt, completion_tokens=completion)]) as server:  # type: ignore[arg-type]
        gen = _backend(server).generate(REQUEST)
    assert gen.text == "ok" and (gen.prompt_tokens, gen.completion_tokens) == counted


@pytest.mark.parametrize(
    ("env", "message"),
    [
        ({"MORE_AGENT_ROOM_MODEL": "roomy?api_key=sk-abcdefgh12345678"}, "room_model: .*credentials"),
        ({"MORE_AGENT_LLM": "openai:gpt-4o?api_key=sk-abcdefgh12345678"}, "llm: .*credentials"),
        ({"OPENAI_BASE_URL": "notaurl"}, "not an http"),
        ({"OPENAI_BASE_URL": "ftp://127.0.0.1/v1"}, "not an http"),
        ({"OPENAI_BASE_URL": "http://127.0.0.1:99999/v1"}, "Port out of range"),
        ({"OPENAI_API_KEY": "sk-abcdefgh12345678\r\nX-Injected: 1"}, "control character"),
        ({"MORE_AGENT_LLM_CONFIG": "/dev/zero"}, "not a regular file"),
    ],
)
def test_settings_that_would_leak_or_cannot_work_are_refused(env: dict[str, str], message: str) -> None:
    with pytest.raises(LLMConfigError, match=message) as e:
        load_llm_config(env=env)
    assert "abcdefgh" not in str(e.value)


@pytest.mark.parametrize("value", ["inf", "nan", "1e300"])
def test_an_endless_timeout_is_refused(value: str, tmp_path: Path) -> None:
    (tmp_path / "llm.toml").write_text(f"timeout_s = {value}\n")
    with pytest.raises(LLMConfigError, match="timeout_s"):
        load_llm_config(tmp_path / "llm.toml", env={})


def test_the_cache_stores_requests_masked(tmp_path: Path) -> None:
    from more_agent.llm.cache import CachedAnswer

    cache = ResponseCache(tmp_path / "c.sqlite")
    cache.put("k", request={"model": "m?api_key=sk-abcdefgh12345678", "messages": ["Bearer abcdefghijklmnop"]},
              purpose="plan", answer=CachedAnswer("a", "m", 1, 1))
    cache.close()
    assert b"abcdefgh" not in (tmp_path / "c.sqlite").read_bytes()
    (row,) = sqlite3.connect(tmp_path / "c.sqlite").execute("SELECT request FROM responses").fetchall()
    assert "***" in row[0]


def test_a_locked_cache_is_transient(tmp_path: Path) -> None:
    holder = sqlite3.connect(tmp_path / "c.sqlite", isolation_level=None)
    holder.execute("CREATE TABLE filler (x)")
    holder.execute("BEGIN EXCLUSIVE")
    try:
        with pytest.raises(CacheLocked, match="locked") as e:
            ResponseCache(tmp_path / "c.sqlite", busy_timeout_s=0.2).get("k")
    finally:
        holder.close()
    assert e.value.retryable
