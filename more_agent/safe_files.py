"""The one path-safety helper: reading and writing files the user or a hostile folder may have rigged.

Every file the project writes into a run or episode folder goes through here, so that

- no write follows a symlink: whole files are written to a temporary sibling and renamed over the
  name (:func:`write_atomic`: a rename replaces a symlink itself, never its target, and a full disk
  leaves the old file or none, never a 0-byte one); appended and locked files are opened with
  ``O_NOFOLLOW`` (:func:`open_nofollow`); a sub-folder that is a symlink is refused (:func:`make_dir`);
- no read is unbounded: :func:`read_bounded` refuses what is not a regular file (``/dev/zero``, a
  FIFO) and anything over a size limit, and drops a UTF-8 byte-order mark;
- an ``OSError`` about a path the user gave (a name over 255 bytes, a read-only folder, a symlink
  loop) becomes one line naming the path (:func:`path_error`), not a traceback.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from more_agent.errors import UserError

MAX_TEXT_BYTES = 64 * 1024 * 1024
"""Largest text file read whole (records, logs of steps, task lists, configs); far above real ones."""

_BAD_PATH_ERRNOS = {
    errno.ENAMETOOLONG: "a name in the path is too long",
    errno.ELOOP: "the path is a symlink loop or a symlink where none may be",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EROFS: "read-only file system",
    errno.ENOTDIR: "a part of the path is not a folder",
    errno.EISDIR: "it is a folder",
    errno.ENOENT: "no such file or folder",
    errno.EEXIST: "it exists already",
}
"""``OSError`` numbers that mean the path the user gave cannot be used: bad input."""

DISK_FULL_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
"""``OSError`` numbers that mean the disk (or a quota, a file-size limit) is full: free space, run again."""


class UnsafePath(UserError):
    """A path cannot be read or written safely (symlink, not a regular file, too large, bad name)."""


def path_error(e: OSError, path: Path | str | None = None) -> UnsafePath | None:
    """One clear :class:`UnsafePath` for an ``OSError`` caused by the path itself, else None."""
    why = _BAD_PATH_ERRNOS.get(e.errno or 0)
    if why is None:
        return None
    where = path if path is not None else (e.filename or "a path")
    return UnsafePath(f"cannot use {_short(str(where))}: {why}")


def _short(text: str, limit: int = 160) -> str:
    """A path shown in one line: its ends kept when it is long."""
    return text if len(text) <= limit else f"{text[:60]}...{text[-60:]}"


def read_bounded(path: Path, *, what: str, max_bytes: int = MAX_TEXT_BYTES) -> str:
    """The UTF-8 text of the regular file ``path`` (a byte-order mark dropped), at most ``max_bytes``."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as e:
        why = _BAD_PATH_ERRNOS.get(e.errno or 0, e.strerror)
        raise UnsafePath(f"cannot read {what} {_short(str(path))}: {why}") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise UnsafePath(f"{what} {_short(str(path))} is not a regular file")
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(max_bytes + 1)
    except OSError as e:
        raise UnsafePath(f"cannot read {what} {_short(str(path))}: {e.strerror}") from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise UnsafePath(f"{what} {_short(str(path))} is larger than {max_bytes} bytes")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise UnsafePath(f"{what} {_short(str(path))} is not UTF-8 text: {e.reason} at byte {e.start}") from None


def open_nofollow(path: Path, flags: int, mode: int = 0o644) -> int:
    """``os.open`` that refuses to follow a symlink at ``path`` (UnsafePath instead of writing through it)."""
    try:
        return os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC, mode)
    except OSError as e:
        if e.errno == errno.ELOOP:
            raise UnsafePath(f"{_short(str(path))} is a symlink; refusing to write through it") from None
        raise


def make_dir(path: Path) -> Path:
    """Create the folder ``path`` (and its parents); refuse one that is a symlink; return it."""
    if path.is_symlink():
        raise UnsafePath(f"{_short(str(path))} is a symlink; refusing to write through it")
    path.mkdir(parents=True, exist_ok=True)
    return path


def write_atomic(path: Path, data: bytes | str, *, durable: bool = True) -> None:
    """Replace ``path`` by ``data`` all at once: a temporary sibling, fsync, rename over the name.

    A symlink at ``path`` is replaced, its target untouched; a write that fails (disk full) removes
    the temporary file and leaves ``path`` as it was. ``durable=False`` skips the fsync (pictures
    and per-step files, many per episode: a crash may lose them, never leave them half-written to
    a reader of this process).
    """
    payload = data.encode("utf-8") if isinstance(data, str) else data
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        fd = open_nofollow(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        try:
            view = memoryview(payload)
            while view:
                view = view[os.write(fd, view) :]
            if durable:
                os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def append_text(path: Path, text: str) -> None:
    """Append ``text`` to ``path`` (created if missing), never through a symlink."""
    fd = open_nofollow(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    try:
        os.write(fd, text.encode("utf-8"))
    finally:
        os.close(fd)
