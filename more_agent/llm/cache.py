"""sqlite response cache shared by parallel evaluation processes.

One table keyed by a sha256 over the request (backend kind, model, messages, sampling parameters,
JSON schema, attempt number). It stores the request for inspection (every string redacted: a model
name or a prompt holding a key is stored masked) and the answer text and token counts; never
credentials (the key is not part of a request). WAL journaling and a busy timeout let several
processes read and write at once; each process opens its own connection (re-opened after a fork).
A cache still locked by another process after the busy timeout is :class:`CacheLocked`, a transient
error (the episode is retryable); any other sqlite failure is :class:`CacheUnusable`, bad input.
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from more_agent.llm import constants as C
from more_agent.llm.errors import CacheLocked, LLMConfigError
from more_agent.redaction import redact_tree


class CacheUnusable(LLMConfigError):
    """The cache file cannot be opened, read or written (a folder, read-only, not a sqlite file)."""


def check_cache_path(path: Path, *, write: bool = True) -> None:
    """Raise CacheUnusable unless ``path`` can serve as the cache file (checked before any request)."""
    hint = f"set {C.ENV_CACHE_PATH} to a writable file path or {C.ENV_CACHE_MODE}=off"
    if path.exists() and not path.is_file():
        raise CacheUnusable(f"LLM cache {path} is not a file; {hint}")
    target = path if path.exists() else next((p for p in path.parents if p.exists()), Path("."))
    if not os.access(target, (os.W_OK if write else os.R_OK)):
        raise CacheUnusable(f"LLM cache {path} is not {'writable' if write else 'readable'}; {hint}")


_SCHEMA = """
CREATE TABLE IF NOT EXISTS responses (
    key TEXT PRIMARY KEY,
    model TEXT NOT NULL,
    purpose TEXT NOT NULL,
    request TEXT NOT NULL,
    text TEXT NOT NULL,
    prompt_tokens INTEGER NOT NULL,
    completion_tokens INTEGER NOT NULL,
    created REAL NOT NULL
)
"""


@dataclass(frozen=True)
class CachedAnswer:
    """What the cache holds for one request."""

    text: str
    model: str
    prompt_tokens: int
    completion_tokens: int


def request_key(request: dict[str, Any]) -> str:
    """sha256 hex digest of the canonical JSON of ``request`` plus the key version."""
    canonical = json.dumps({"v": C.CACHE_KEY_VERSION, **request}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


class ResponseCache:
    """A sqlite file of answers; safe for concurrent processes. Opens lazily on first use."""

    def __init__(self, path: Path | str, *, busy_timeout_s: float = C.CACHE_BUSY_TIMEOUT_S) -> None:
        self.path = Path(path)
        self._busy_timeout_s = busy_timeout_s
        self._conn: sqlite3.Connection | None = None
        self._pid = -1

    def _connection(self) -> sqlite3.Connection:
        """This process's connection, created (with table and WAL mode) on first use."""
        try:
            return self._open()
        except (sqlite3.Error, OSError) as e:
            raise self._error("open", e) from None

    def _error(self, doing: str, e: Exception) -> CacheLocked | CacheUnusable:
        """The typed error of a failed sqlite operation: locked or busy is transient, the rest is not."""
        if isinstance(e, sqlite3.OperationalError) and ("locked" in str(e) or "busy" in str(e)):
            return CacheLocked(
                f"LLM cache {self.path} stayed locked by another process for {self._busy_timeout_s:g} s: {e}"
            )
        return CacheUnusable(f"cannot {doing} LLM cache {self.path}: {e}")

    def _open(self) -> sqlite3.Connection:
        if self._conn is None or self._pid != os.getpid():
            self.path.parent.mkdir(parents=True, exist_ok=True)
            conn = sqlite3.connect(self.path, timeout=self._busy_timeout_s, isolation_level=None)
            conn.execute(f"PRAGMA busy_timeout = {int(self._busy_timeout_s * 1000)}")
            conn.execute("PRAGMA journal_mode = WAL")
            conn.execute("PRAGMA synchronous = NORMAL")
            conn.execute(_SCHEMA)
            self._conn, self._pid = conn, os.getpid()
        return self._conn

    def get(self, key: str) -> CachedAnswer | None:
        """The stored answer for ``key``, or None."""
        try:
            row = (
                self._connection()
                .execute("SELECT text, model, prompt_tokens, completion_tokens FROM responses WHERE key = ?", (key,))
                .fetchone()
            )
        except sqlite3.Error as e:
            raise self._error("read", e) from None
        return CachedAnswer(*row) if row else None

    def put(self, key: str, *, request: dict[str, Any], purpose: str, answer: CachedAnswer) -> None:
        """Store (or overwrite) the answer for ``key``."""
        try:
            self._insert(key, request=request, purpose=purpose, answer=answer)
        except sqlite3.Error as e:
            raise self._error("write", e) from None

    def _insert(self, key: str, *, request: dict[str, Any], purpose: str, answer: CachedAnswer) -> None:
        self._connection().execute(
            "INSERT OR REPLACE INTO responses VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            (
                key,
                answer.model,
                purpose,
                json.dumps(redact_tree(request), sort_keys=True),
                answer.text,
                answer.prompt_tokens,
                answer.completion_tokens,
                time.time(),
            ),
        )

    def __len__(self) -> int:
        return int(self._connection().execute("SELECT COUNT(*) FROM responses").fetchone()[0])

    def close(self) -> None:
        """Close this process's connection (a later use re-opens it)."""
        if self._conn is not None and self._pid == os.getpid():
            self._conn.close()
        self._conn = None
