"""Token usage and cost: a small price table, per-call cost, and a meter summing an episode's calls.

Prices are USD per million tokens from the providers' public price lists (list prices, no batch or
cached-input discounts). A dated snapshot name such as ``gpt-4o-2024-08-06`` is priced as its base
name. A model missing from the table costs 0 and is flagged (``cost_known=False``) rather than
guessed; add it with the ``prices`` config field.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from more_agent.llm.completion import Completion
from more_agent.llm.config import ModelPrice

PRICES: Mapping[str, ModelPrice] = {
    "gpt-4o": ModelPrice(input_per_m=2.50, output_per_m=10.00),
    "gpt-4o-mini": ModelPrice(input_per_m=0.15, output_per_m=0.60),
    "gpt-4.1": ModelPrice(input_per_m=2.00, output_per_m=8.00),
    "gpt-4.1-mini": ModelPrice(input_per_m=0.40, output_per_m=1.60),
    "gpt-4.1-nano": ModelPrice(input_per_m=0.10, output_per_m=0.40),
    "gpt-4-turbo": ModelPrice(input_per_m=10.00, output_per_m=30.00),
    "gpt-4": ModelPrice(input_per_m=30.00, output_per_m=60.00),
    "gpt-3.5-turbo": ModelPrice(input_per_m=0.50, output_per_m=1.50),
    "o3-mini": ModelPrice(input_per_m=1.10, output_per_m=4.40),
}

MAX_TOKENS_PER_CALL = 10_000_000
"""Largest token count one answer's usage may report (context windows are far smaller)."""

_SNAPSHOT_SUFFIX = re.compile(r"-\d{4}-\d{2}-\d{2}$|-\d{4}$")


def price_of(model: str, extra: Mapping[str, ModelPrice] | None = None) -> ModelPrice | None:
    """The price of ``model`` (``extra`` first, then the table, then without a date suffix), or None."""
    table = {**PRICES, **(extra or {})}
    for name in (model, _SNAPSHOT_SUFFIX.sub("", model)):
        if name in table:
            return table[name]
    return None


def token_count(value: object) -> int:
    """A server's token count as this project counts it: an integer in [0, MAX_TOKENS_PER_CALL], else 0.

    A server has sent negative counts (a cost of -$752), 1e300 and null; none of them is a count,
    so the answer is kept and its usage counted as unknown (0), never as a number that cannot be.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return 0
    if isinstance(value, float) and not value.is_integer():
        return 0
    return int(value) if 0 <= value <= MAX_TOKENS_PER_CALL else 0


def cost_usd(price: ModelPrice, prompt_tokens: int, completion_tokens: int) -> float:
    """USD for one call."""
    return (prompt_tokens * price.input_per_m + completion_tokens * price.output_per_m) / 1e6


@dataclass
class UsageMeter:
    """Running totals of LLM calls; tokens count every answer, cost only what was actually paid.

    One meter per episode (or per client); ``add`` each :class:`~more_agent.llm.completion.Completion`.
    Field names match :class:`more_agent.records.LLMUsage` so ``LLMUsage(**meter.totals())`` works.
    """

    calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cost_usd: float = 0.0
    cache_hits: int = 0
    images: int = 0
    image_bytes: int = 0
    image_tokens: int = 0
    reasoning_tokens: int = 0
    unpriced_models: set[str] = field(default_factory=set)

    def add(self, completion: Completion) -> None:
        """Count one completion."""
        self.calls += 1
        self.prompt_tokens += completion.usage.prompt_tokens
        self.completion_tokens += completion.usage.completion_tokens
        self.cost_usd += completion.cost_usd
        self.cache_hits += int(completion.cached)
        self.images += completion.images
        self.image_bytes += completion.image_bytes
        self.image_tokens += completion.image_tokens
        self.reasoning_tokens += reasoning_tokens(completion)
        if not completion.cost_known:
            self.unpriced_models.add(completion.model)

    def totals(self) -> dict[str, int | float]:
        """The totals as a plain dict (without the unpriced model names)."""
        return {
            "calls": self.calls,
            "prompt_tokens": self.prompt_tokens,
            "completion_tokens": self.completion_tokens,
            "cost_usd": self.cost_usd,
            "cache_hits": self.cache_hits,
            "images": self.images,
            "image_bytes": self.image_bytes,
            "image_tokens": self.image_tokens,
            "reasoning_tokens": self.reasoning_tokens,
        }


REASONING_FIELDS = ("analysis", "reasoning")
"""Free-text answer fields a model reasons in before its command (:data:`more_agent.llm.grammar.FREE_TEXT_FIELDS`)."""


def reasoning_tokens(completion: Completion) -> int:
    """Answer tokens spent on reasoning: the answer's tokens in the share of its characters that its
    free-text fields hold (servers count tokens per answer, not per field)."""
    parsed, text = completion.parsed, completion.text
    if not parsed or not text:
        return 0
    chars = sum(len(v) for k in REASONING_FIELDS if isinstance(v := parsed.get(k), str))
    return round(completion.usage.completion_tokens * min(1.0, chars / len(text)))
