"""An exclusive lock on a run folder: one writer at a time appends to ``episodes.jsonl``.

Two ``more-agent eval --resume`` on one folder would both run every missing episode and record it
twice. The writer holds ``flock`` on ``DIR/.lock`` for the whole run; the operating system drops
the lock when the process ends, however it ends (kill -9 included), so a stale lock never blocks a
resume. The file says who holds it, for the message the second writer gets. ``more-agent run`` takes
the same lock on its episode folder. A ``.lock`` that is a symlink is refused (never followed). POSIX only.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from more_agent.errors import UserError
from more_agent.safe_files import open_nofollow

LOCK_FILE = ".lock"
"""Name of the lock file inside a run folder."""


class RunFolderBusy(UserError):
    """Another process is writing to the run folder."""


@contextmanager
def locked_run_dir(run_dir: Path) -> Iterator[None]:
    """Hold the exclusive lock of ``run_dir`` (created if missing); raise RunFolderBusy naming the holder."""
    import fcntl

    run_dir.mkdir(parents=True, exist_ok=True)
    fd = open_nofollow(run_dir / LOCK_FILE, os.O_RDWR | os.O_CREAT)  # a symlinked .lock is refused, its target kept
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 512, 0).decode("utf-8", "replace").strip() or "another process"
            raise RunFolderBusy(
                f"{run_dir} is being written by {holder}; wait for that run to end or choose another --out"
            ) from None
        os.ftruncate(fd, 0)
        stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime())
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()} since {stamp}\n".encode(), 0)
        try:
            yield
        finally:
            os.ftruncate(fd, 0)
            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)
