"""Plain data types of one LLM exchange: chat messages, token usage, the completion returned."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, TypedDict


class ChatMessage(TypedDict):
    """One chat message as the OpenAI chat API takes it."""

    role: Literal["system", "user", "assistant"]
    content: str | list[dict[str, Any]]
    """Text, or a list of content parts (text and base64 PNG ``image_url`` parts: :mod:`more_agent.llm.images`)."""


@dataclass(frozen=True)
class TokenUsage:
    """Tokens of one answer as the server counted them."""

    prompt_tokens: int = 0
    completion_tokens: int = 0


@dataclass(frozen=True)
class Completion:
    """One answer of a model, fresh or from the cache.

    ``usage`` is the answer's token count (the same for a cache hit); ``cost_usd`` is what this call
    paid (0 for a cache hit or an unpriced model; ``cost_known`` tells the two apart).
    """

    text: str
    parsed: dict[str, Any] | None
    """The JSON object in the answer when a schema was asked for, else None."""
    model: str
    usage: TokenUsage
    cost_usd: float
    cost_known: bool
    cached: bool
    latency_s: float
    """Seconds the call took here (a cache lookup for hits)."""
    attempts: int
    """HTTP attempts made (0 for a cache hit)."""
    purpose: str
    """What the call was for ('plan', 'filter', 'room', ...), for logs and replay errors."""
    images: int = 0
    """Images in the request."""
    image_bytes: int = 0
    """Bytes of those images (decoded PNG)."""
    image_tokens: int = 0
    """Prompt tokens OpenAI bills for them (:func:`more_agent.llm.images.image_tokens`); part of ``usage.prompt_tokens``
    when the server counts images, as OpenAI's does."""
