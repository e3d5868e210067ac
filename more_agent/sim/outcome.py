"""What every step of the world reports back: success, a typed reason when it failed, and feedback."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Generic, TypeVar

Reason = TypeVar("Reason", bound=Enum)


@dataclass(frozen=True)
class Outcome(Generic[Reason]):
    """Success, the reason of a failure (None on success) and feedback in words for the planner."""

    ok: bool
    reason: Reason | None
    feedback: str
