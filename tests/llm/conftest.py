"""Fixtures of the LLM tests: a scripted fake OpenAI server and configs pointing at it."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from more_agent.llm import LLMConfig
from tests.fakes.openai_server import FakeOpenAIServer

TEST_API_KEY = "sk-test-DO-NOT-LEAK-0123456789"


@pytest.fixture
def fake_openai() -> Iterator[FakeOpenAIServer]:
    """A started fake server with an empty script; tests ``push`` what it should answer."""
    with FakeOpenAIServer() as server:
        yield server


@pytest.fixture
def llm_config(fake_openai: FakeOpenAIServer, tmp_path: Path) -> LLMConfig:
    """A config for the fake server: tiny backoff, a fresh cache file, and a deadline (10 s) that a scripted answer
    meets on a worker loaded by the others (a test of timeouts sets its own)."""
    return LLMConfig(
        base_url=fake_openai.base_url,
        api_key=TEST_API_KEY,
        timeout_s=10.0,
        max_retries=2,
        backoff_initial_s=0.01,
        backoff_max_s=0.05,
        cache_path=tmp_path / "cache.sqlite",
    )
