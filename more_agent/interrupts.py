"""Ctrl-C that cannot be lost: a SIGINT handler that remembers it was pressed.

A KeyboardInterrupt raised inside native code (a numba callback, a C extension) can come back as
another exception that an episode records as an ordinary error, and the run would finish with exit
status 0. The CLI runs every command within :func:`sigint_remembered`; long loops check :func:`interrupted`
and stop, and the CLI exits with status 130 whenever Ctrl-C was pressed.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

_pressed = threading.Event()


def _on_sigint(signum: int, frame: FrameType | None) -> None:
    _pressed.set()
    raise KeyboardInterrupt


@contextmanager
def sigint_remembered() -> Iterator[None]:
    """Within the block, remember every Ctrl-C (and raise KeyboardInterrupt as usual); main thread only."""
    _pressed.clear()
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, _on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def interrupted() -> bool:
    """Whether Ctrl-C was pressed since the handler was installed."""
    return _pressed.is_set()
