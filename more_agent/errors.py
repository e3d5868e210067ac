"""User-facing errors: bad names, bad files, bad configs. The CLI turns them into exit status 2."""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable
from pathlib import Path


class UserError(Exception):
    """Something the user asked for cannot be done; the message says what and what to use instead."""


def closest_names(name: str, candidates: Iterable[str], n: int = 5) -> list[str]:
    """Up to ``n`` valid names closest to ``name`` (difflib ratio), best first."""
    return difflib.get_close_matches(name, list(candidates), n=n, cutoff=0.4)


def unknown_name_error(kind: str, name: str, candidates: Iterable[str]) -> UserError:
    """A UserError for an unknown task/scene/... name that lists the closest valid names."""
    close = closest_names(name, candidates)
    hint = f"; closest: {', '.join(close)}" if close else ""
    return UserError(f"unknown {kind} {name!r}{hint}")


def check_writable_dir(path: Path, what: str = "--out") -> None:
    """Raise a UserError unless ``path`` is, or can be created as, a writable directory."""
    if path.is_symlink() and not path.exists():
        raise UserError(f"{what} {path} is a symlink to nothing (dangling, or a loop)")
    if path.exists() and not path.is_dir():
        raise UserError(f"{what} {path} exists and is not a directory")
    existing = next((p for p in (path, *path.parents) if p.exists()), Path("."))
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise UserError(f"cannot write to {path}: {existing} is not a writable directory")
