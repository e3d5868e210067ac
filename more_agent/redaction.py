"""Keeping credentials out of everything the project writes or prints.

The first line of defence is refusing them where they come in (LLM specs, base URLs); this module
is the second: :func:`redact` replaces anything key-shaped (``sk-...`` keys, ``api_key=...``
parameters, ``user:password@`` in URLs, bearer tokens, and the literal keys this process was
configured with) by ``***``. It is applied to error messages, tracebacks, log lines, and through
:func:`redact_tree` to every string of what is written as JSON (records, run.json, the cache's request
column). :func:`for_terminal` also strips the escape sequences a server or a scene file may carry,
before text reaches a terminal.
"""

from __future__ import annotations

import re
from typing import Any

MASK = "***"

_PARAM = re.compile(r"(?i)\b(api[_-]?key|access[_-]?token|token|secret|password|passwd)=[^&;\s'\"]*")
_USERINFO = re.compile(r"(?i)\b([a-z][a-z0-9+.\-]*://)[^/\s@]+@")
_BEARER = re.compile(r"(?i)\b(bearer\s+)[A-Za-z0-9._~+/=\-]{8,}")
_KEY_LIKE = re.compile(r"\b(?:sk|rk)-[A-Za-z0-9_\-]{8,}|\b(?:hf|ghp|gho|xoxb|xoxp)_[A-Za-z0-9]{16,}")

_known: set[str] = set()

MIN_SECRET_CHARS = 6
"""Registered values shorter than this are not searched for (they would mask ordinary words)."""


def register_secret(value: str | None) -> None:
    """Also redact this literal value (a configured API key) wherever it appears in this process."""
    if value and len(value) >= MIN_SECRET_CHARS:
        _known.add(value)


def redact(text: str) -> str:
    """``text`` with every key-shaped substring replaced by ``***``."""
    for value in _known:
        text = text.replace(value, MASK)
    text = _PARAM.sub(lambda m: f"{m.group(1)}={MASK}", text)
    text = _USERINFO.sub(lambda m: f"{m.group(1)}{MASK}@", text)
    text = _BEARER.sub(lambda m: f"{m.group(1)}{MASK}", text)
    return _KEY_LIKE.sub(MASK, text)


def has_credentials(text: str) -> bool:
    """Whether ``text`` holds something :func:`redact` would mask."""
    return redact(text) != text


def redact_tree(value: Any) -> Any:
    """``value`` (JSON-like: dicts, lists, strings, numbers) with every string :func:`redact`-ed."""
    if isinstance(value, str):
        return redact(value)
    if isinstance(value, dict):
        return {redact_tree(k): redact_tree(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [redact_tree(v) for v in value]
    return value


_CONTROL = re.compile(r"\x1b\[[0-?]*[ -/]*[@-~]|\x1b\][^\x07\x1b]*(?:\x07|\x1b\\)?|[\x00-\x08\x0b-\x1f\x7f-\x9f]")
"""ANSI CSI and OSC sequences, and every other control character but tab and newline."""


def for_terminal(text: str) -> str:
    """``text`` redacted and without escape sequences or control characters (a server's error text, a
    scene name: they could recolour, retitle or clear the terminal)."""
    return _CONTROL.sub("", redact(text))
