"""Every LLM request and answer of a high-level step, as plain JSON for ``steps.jsonl`` and the viewer.

:class:`RecordingClient` wraps an :class:`~more_agent.llm.client.LLMClient` and appends one
:class:`Exchange` per call (the messages sent, the answer, tokens, latency, cache hit) to a shared
list, so that room labels, filter, plan and every re-ask are kept without touching the callers.
Calls that raise (timeouts, a server gone) leave no exchange: they have no answer.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from more_agent.llm.client import LLMClient
from more_agent.llm.completion import ChatMessage, Completion
from more_agent.llm.errors import Unparseable


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


class RecordingClient:
    """An LLM client that forwards every call to ``inner`` and appends the exchange to ``log``."""

    def __init__(self, inner: LLMClient, log: list[Exchange]) -> None:
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
            self.log.append(Exchange(tuple(messages), e.completion))
            raise
        self.log.append(Exchange(tuple(messages), completion))
        return completion
