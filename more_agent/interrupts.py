"""Ctrl-C and SIGTERM that cannot be lost: signal handlers that remember the signal came.

A KeyboardInterrupt raised inside native code (a numba callback, a C extension) can come back as
another exception that an episode records as an ordinary error, and the run would finish with exit
status 0. The CLI runs every command within :func:`signals_remembered`; long loops check
:func:`interrupted` and stop, and the CLI exits with :func:`signal_exit_status` (130 for Ctrl-C,
143 for SIGTERM) whenever one came. Only the first signal raises (as KeyboardInterrupt); later ones
are remembered but raise nothing, so a second Ctrl-C cannot break the clean-up into "Exception
ignored" noise, and after an interrupted command the signals stay ignored while the process exits.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

_received: list[int] = []
"""Signal numbers received since the handlers were installed, in order."""

HANDLED = (signal.SIGINT, signal.SIGTERM)


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    if len(_received) == 1:
        raise KeyboardInterrupt


@contextmanager
def signals_remembered() -> Iterator[None]:
    """Within the block, remember SIGINT and SIGTERM (the first raises KeyboardInterrupt); main thread only."""
    _received.clear()
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _on_signal) for s in HANDLED}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, signal.SIG_IGN if _received else handler)


def interrupted() -> bool:
    """Whether Ctrl-C or SIGTERM came since the handlers were installed."""
    return bool(_received)


def signal_exit_status() -> int:
    """The exit status for the first signal received: 128 + its number (130 SIGINT, 143 SIGTERM)."""
    return 128 + (_received[0] if _received else signal.SIGINT)


def ignore_interrupts() -> None:
    """In a worker process: leave Ctrl-C to the parent, which stops the workers itself."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
