"""One limit on concurrent LLM calls across all episode workers.

``LLMConcurrencyLimiter`` is the protocol an LLM client acquires around each request (``with
llm_limiter(): ...``). Implementations: ``NullLimiter`` (no limit, in-process runs),
``ProcessLimiter`` (a multiprocessing semaphore shared with the process pool's workers) and
``more_agent.eval.ray_backend.RayLimiter`` (a Ray actor semaphore). The harness installs the
limiter of the current worker with ``set_llm_limiter``; a client is given one at construction
(``ChatClient(limiter=...)``) and otherwise takes the one installed in its process (``llm_limiter()``).
"""

from __future__ import annotations

from types import TracebackType
from typing import Any, Protocol, runtime_checkable


@runtime_checkable
class LLMConcurrencyLimiter(Protocol):
    """A counting semaphore over LLM calls, usable as a context manager."""

    def acquire(self) -> None:
        """Block until a call slot is free, then take it."""

    def release(self) -> None:
        """Give the slot back."""

    def __enter__(self) -> LLMConcurrencyLimiter: ...

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None: ...


class SlotContext:
    """``with limiter:`` acquires on entry and releases on exit."""

    def acquire(self) -> None:  # pragma: no cover - overridden
        raise NotImplementedError

    def release(self) -> None:  # pragma: no cover - overridden
        raise NotImplementedError

    def __enter__(self) -> SlotContext:
        self.acquire()
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.release()


class NullLimiter(SlotContext):
    """No limit: acquire and release do nothing."""

    def acquire(self) -> None:
        """Return at once."""

    def release(self) -> None:
        """Do nothing."""


class ProcessLimiter(SlotContext):
    """A limit shared by the processes of one pool, through a multiprocessing semaphore.

    Build it in the parent with the pool's context and pass it to the workers at start-up
    (``initargs``): multiprocessing semaphores travel only by inheritance.
    """

    def __init__(self, semaphore: Any) -> None:
        self._semaphore = semaphore

    @classmethod
    def create(cls, ctx: Any, max_concurrent: int) -> ProcessLimiter:
        """A limiter allowing ``max_concurrent`` calls, from a multiprocessing context ``ctx``."""
        if max_concurrent < 1:
            raise ValueError(f"max_concurrent must be >= 1, got {max_concurrent}")
        return cls(ctx.BoundedSemaphore(max_concurrent))

    def acquire(self) -> None:
        """Block until a slot is free."""
        self._semaphore.acquire()

    def release(self) -> None:
        """Give the slot back."""
        self._semaphore.release()


_current: LLMConcurrencyLimiter = NullLimiter()


def set_llm_limiter(limiter: LLMConcurrencyLimiter | None) -> None:
    """Install the limiter of this process (None restores the no-op one)."""
    global _current
    _current = limiter if limiter is not None else NullLimiter()


def llm_limiter() -> LLMConcurrencyLimiter:
    """The limiter an LLM client of this process should hold around each request."""
    return _current
