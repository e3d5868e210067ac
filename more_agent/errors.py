"""User-facing errors: bad names, bad files, bad configs. The CLI turns them into exit status 2."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


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
