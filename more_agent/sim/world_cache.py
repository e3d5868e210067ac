"""Instantiated worlds kept on disk: every planner of a sweep runs on the worlds the first one built.

A task instance (:func:`~more_agent.sim.instantiate.instantiate`) is a function of its arguments, of the
scene file it names (when it names one) and of the code and data that build it. The cache keys each
instance by a sha256 over all of them: the arguments, the scene file's bytes, and a fingerprint of this
package's files and of the versions of Python, numpy, scipy and bddl (their random streams and task
files). A world built by other code is never read; rows of another fingerprint are dropped on the first
write. Instances are pickled into one sqlite file that parallel workers share (a busy timeout; each
process opens its own connection).

Building a world is about a twentieth of a grounded episode and a third of an oracle one (docs/benchmarks.md);
a sweep of seven planners over 165 worlds builds each once. ``MORE_AGENT_WORLD_CACHE`` names the file
(default ``~/.cache/more-agent/worlds.sqlite``), or ``off``. The cache never costs an episode: a file it
cannot read or write, or a row it cannot load, is logged and the world is built as without it.

Beside each world the cache keeps, as JSON, what a listing shows of it (:func:`summary_cached`): ``tasks show``
reads that without unpickling the world, whose modules import numba and scipy (a second), or checking its
goal again.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import logging
import os
import pickle
import sqlite3
import sys
from collections.abc import Callable
from contextlib import closing
from functools import cache, partial
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    from more_agent.sim.instantiate import TaskInstance

ENV_WORLD_CACHE = "MORE_AGENT_WORLD_CACHE"
"""The cache's sqlite file, or ``off``."""

DEFAULT_WORLD_CACHE = Path.home() / ".cache" / "more-agent" / "worlds.sqlite"

BUSY_TIMEOUT_S = 30.0
"""How long a worker waits for another's write (a row is a few hundred kB)."""

log = logging.getLogger(__name__)


def world_cache_path() -> Path | None:
    """The cache file ``MORE_AGENT_WORLD_CACHE`` names (the default when unset), None when it says ``off``."""
    value = os.environ.get(ENV_WORLD_CACHE, "").strip()
    if value.lower() == "off":
        return None
    return Path(value).expanduser() if value else DEFAULT_WORLD_CACHE


@cache
def code_fingerprint() -> str:
    """sha256 over this package's source and data files and the versions of what builds a world with it."""
    digest = hashlib.sha256()
    root = Path(__file__).resolve().parents[1]
    for path in sorted(p for p in root.rglob("*") if p.suffix in (".py", ".json") and "__pycache__" not in p.parts):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    versions = [sys.version, *(version(name) for name in ("numpy", "scipy", "bddl"))]
    digest.update(json.dumps(versions).encode())
    return digest.hexdigest()


def instance_key(task: str, scene: str | None, seed: int, *, start: str, distractors: bool, descriptions: str) -> str:
    """The cache key of an instance: its arguments, the bytes of a scene file, the code fingerprint."""
    scene_bytes = Path(scene).read_bytes() if scene is not None and scene.endswith(".json") else b""
    fields = [code_fingerprint(), task, scene, seed, start, distractors, descriptions]
    return hashlib.sha256(json.dumps(fields).encode() + b"\0" + scene_bytes).hexdigest()


def instantiate_cached(
    task: str,
    scene: str | None = None,
    seed: int = 0,
    *,
    start: str = "random",
    distractors: bool = True,
    descriptions: str = "named",
) -> TaskInstance:
    """:func:`~more_agent.sim.instantiate.instantiate`, reading the instance from the world cache when it
    holds it and writing it there when not. Bad input raises as ``instantiate`` does (nothing is cached)."""
    from more_agent.sim.instantiate import instantiate

    build = partial(instantiate, task, scene, seed, start=start, distractors=distractors, descriptions=descriptions)
    path = world_cache_path()
    if path is None:
        return build()
    try:
        key = instance_key(*build.args, **build.keywords)
    except OSError:  # an unreadable scene file: instantiate says what is wrong with it
        return build()
    instance = _read(path, "worlds", key, _unpickle_instance)
    if instance is None:
        instance = build()
        _write(path, "worlds", key, lambda: pickle.dumps(instance, protocol=pickle.HIGHEST_PROTOCOL))
    return instance


def summary_cached(
    kind: str, task: str, scene: str | None, seed: int, summarize: Callable[[TaskInstance], dict[str, Any]]
) -> dict[str, Any]:
    """``summarize`` of the instance :func:`instantiate_cached` gives for these arguments (the other settings
    at their defaults), read from the JSON the cache keeps under ``kind`` beside the world when it holds it."""
    defaults = {
        name: p.default
        for name, p in inspect.signature(instantiate_cached).parameters.items()
        if p.kind is p.KEYWORD_ONLY  # start, distractors, descriptions: the ones run drives
    }

    def build() -> dict[str, Any]:
        return summarize(instantiate_cached(task, scene, seed, **defaults))

    path = world_cache_path()
    if path is None:
        return build()
    try:
        key = f"{kind}:{instance_key(task, scene, seed, **defaults)}"
    except OSError:  # an unreadable scene file: instantiate says what is wrong with it
        return build()
    summary = _read(path, "summaries", key, _json_object)
    if summary is None:
        summary = build()
        _write(path, "summaries", key, partial(json.dumps, summary))
    return summary


def _connect(path: Path) -> sqlite3.Connection:
    connection = sqlite3.connect(path, timeout=BUSY_TIMEOUT_S, isolation_level=None)
    connection.execute(
        "CREATE TABLE IF NOT EXISTS worlds (key TEXT PRIMARY KEY, fingerprint TEXT NOT NULL, instance BLOB NOT NULL)"
    )
    connection.execute(
        "CREATE TABLE IF NOT EXISTS summaries (key TEXT PRIMARY KEY, fingerprint TEXT NOT NULL, summary TEXT NOT NULL)"
    )
    return connection


def _unpickle_instance(blob: bytes) -> TaskInstance | None:
    from more_agent.sim.instantiate import TaskInstance

    instance = pickle.loads(blob)
    return instance if isinstance(instance, TaskInstance) else None


def _json_object(text: str) -> dict[str, Any] | None:
    value = json.loads(text)
    return value if isinstance(value, dict) else None


_T = TypeVar("_T")


def _read(path: Path, table: str, key: str, load: Callable[[Any], _T | None]) -> _T | None:
    """The row ``key`` of ``table`` (``worlds`` or ``summaries``) as ``load`` reads it; None when absent or unreadable."""
    if not path.is_file():
        return None
    try:
        with closing(_connect(path)) as connection:
            row = connection.execute(f"SELECT * FROM {table} WHERE key = ?", (key,)).fetchone()
        return load(row[2]) if row is not None else None
    except Exception as e:  # noqa: BLE001 - a cache that fails is a cache miss, never a lost episode
        log.warning("world cache %s unreadable, building anew: %s: %s", path, type(e).__name__, e)
        return None


def _write(path: Path, table: str, key: str, dump: Callable[[], bytes | str]) -> None:
    """Writes ``dump()`` as the row ``key`` of ``table``, dropping every row another code fingerprint wrote."""
    try:
        value = dump()
        path.parent.mkdir(parents=True, exist_ok=True)
        with closing(_connect(path)) as connection:
            for stale in ("worlds", "summaries"):
                connection.execute(f"DELETE FROM {stale} WHERE fingerprint != ?", (code_fingerprint(),))
            connection.execute(f"INSERT OR REPLACE INTO {table} VALUES (?, ?, ?)", (key, code_fingerprint(), value))
    except Exception as e:  # noqa: BLE001 - the episode goes on with the world it built
        log.warning("world cache %s not written: %s: %s", path, type(e).__name__, e)
