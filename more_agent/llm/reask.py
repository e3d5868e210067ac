"""Bounded re-asking: ask, validate, on a bad answer tell the model why and ask again, then give up typed.

The episode loop never crashes on LLM output: after ``max_reasks`` re-asks the last reason is raised
as :class:`~more_agent.llm.errors.InvalidAnswer`, which the loop counts as an invalid action and feeds
back to the planner. Transport errors (timeouts, ...) are not caught here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from pydantic import BaseModel

from more_agent.llm.client import LLMClient
from more_agent.llm.completion import ChatMessage, Completion
from more_agent.llm.errors import InvalidAnswer, Unparseable
from more_agent.llm.limits import MAX_ECHO_CHARS, clip

T = TypeVar("T")

REASK_TEMPLATE = "That answer cannot be used: {reason}\nAnswer again with one JSON object in the requested format."
"""User message appended after an invalid answer."""


@dataclass(frozen=True)
class Validated(Generic[T]):
    """A validated value and every completion it took (for usage accounting and logs)."""

    value: T
    completions: tuple[Completion, ...]


def ask_validated(
    client: LLMClient,
    messages: Sequence[ChatMessage],
    schema: type[BaseModel] | None,
    validate: Callable[[str | Mapping[str, Any]], T],
    *,
    max_reasks: int = 2,
    purpose: str = "",
) -> Validated[T]:
    """Ask until ``validate`` accepts the answer (its JSON object, else its text), at most ``max_reasks`` re-asks.

    ``validate`` raises InvalidAnswer with a reason the model can act on. Raises InvalidAnswer with
    the last reason and all completions when no answer was accepted.
    """
    conversation = list(messages)
    completions: list[Completion] = []
    reason = ""
    for _ in range(max_reasks + 1):
        try:
            completion = client.complete(conversation, schema=schema, purpose=purpose)
            answer: str | Mapping[str, Any] = completion.parsed if completion.parsed is not None else completion.text
            completions.append(completion)
            return Validated(validate(answer), tuple(completions))
        except Unparseable as e:
            completion, reason = e.completion, e.reason
            completions.append(completion)
        except InvalidAnswer as e:
            reason = e.reason
        conversation += [
            ChatMessage(role="assistant", content=clip(completion.text, MAX_ECHO_CHARS)),
            ChatMessage(role="user", content=REASK_TEMPLATE.format(reason=reason)),
        ]
    raise InvalidAnswer(reason, completions=tuple(completions))
