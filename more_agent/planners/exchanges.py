"""Every LLM request and answer of a planner: the episode's usage, metered once, and each step's
exchanges as plain JSON for ``steps.jsonl`` and the viewer.

:class:`RecordingClient` wraps an :class:`~more_agent.llm.client.LLMClient` and adds one
:class:`Exchange` per call (the messages sent, the answer, tokens, latency, cache hit) to a shared
:class:`CallLog`, so that room labels, filter, plan and every re-ask are counted and kept without
touching the callers. Calls that raise (timeouts, a server gone) leave no exchange: they have no answer.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from more_agent.llm.client import LLMClient
from more_agent.llm.completion import ChatMessage, Completion
from more_agent.llm.errors import Unparseable
from more_agent.llm.usage import UsageMeter
from more_agent.records import LLMUsage


@dataclass(frozen=True)
class Exchange:
    """One LLM call: what was sent and what came back."""

    messages: tuple[ChatMessage, ...]
    completion: Completion

    def to_json(self) -> dict[str, Any]:
        """The exchange as a JSON-ready dict (message contents as sent: text, or a list of parts for a VLM)."""
        c = self.completion
        return {
            "purpose": c.purpose,
            "model": c.model,
            "messages": [dict(m) for m in self.messages],
            "answer": c.text,
            "prompt_tokens": c.usage.prompt_tokens,
            "completion_tokens": c.usage.completion_tokens,
            "latency_s": round(c.latency_s, 4),
            "cached": c.cached,
        }


class CallLog:
    """The LLM calls of a planner: usage and waiting time of the episode, exchanges of the current step."""

    def __init__(self) -> None:
        self.exchanges: list[Exchange] = []
        self.meter = UsageMeter()
        self.seconds = 0.0
        """Time spent waiting for answers this episode (cache lookups included)."""

    def add(self, exchange: Exchange) -> None:
        """Count a call as soon as its answer arrives (an LLM error later keeps it)."""
        self.exchanges.append(exchange)
        self.meter.add(exchange.completion)
        self.seconds += exchange.completion.latency_s

    def usage(self) -> LLMUsage:
        """The episode's traffic so far."""
        return LLMUsage(**self.meter.totals(), seconds=self.seconds)

    def new_step(self) -> None:
        """Forget the previous step's exchanges."""
        self.exchanges.clear()

    def new_episode(self) -> None:
        """Start counting from zero."""
        self.new_step()
        self.meter, self.seconds = UsageMeter(), 0.0


class RecordingClient:
    """An LLM client that forwards every call to ``inner`` and adds the exchange to ``log``."""

    def __init__(self, inner: LLMClient, log: CallLog) -> None:
        self.inner = inner
        self.log = log

    @property
    def model(self) -> str:
        """The wrapped client's model."""
        return self.inner.model

    def __getattr__(self, name: str) -> Any:
        """Anything else (a cache, a backend) is the wrapped client's, so the wrapper stays transparent."""
        return getattr(self.inner, name)

    def complete(
        self,
        messages: Sequence[ChatMessage],
        *,
        schema: type[BaseModel] | None = None,
        purpose: str = "",
        attempt: int = 0,
    ) -> Completion:
        """Forward the call; record it when it returns an answer (an Unparseable answer is recorded too)."""
        try:
            completion = self.inner.complete(messages, schema=schema, purpose=purpose, attempt=attempt)
        except Unparseable as e:
            self.log.add(Exchange(tuple(messages), e.completion))
            raise
        self.log.add(Exchange(tuple(messages), completion))
        return completion
