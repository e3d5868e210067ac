"""Running one episode in any process: the episode function named by its dotted path, and the record
of an episode that raised or whose worker died. Shared by the process pool and the Ray backend."""

from __future__ import annotations

import importlib
import time
import traceback
from collections.abc import Callable
from pathlib import Path

from more_agent.errors import UserError
from more_agent.eval.episode_folder import folder_record
from more_agent.eval.store import episode_dir, of_spec
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.redaction import redact

EpisodeFn = Callable[..., EpisodeRecord]


def resolve_episode_fn(path: str) -> EpisodeFn:
    """Import an episode function from 'pkg.module:function' (or 'pkg.module.function')."""
    module, sep, name = path.partition(":")
    if not sep:
        module, _, name = path.rpartition(".")
    try:
        fn = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError, ValueError) as e:
        raise UserError(f"cannot import episode function {path!r}: {e}") from None
    if not callable(fn):
        raise UserError(f"episode function {path!r} is not callable")
    return fn


def error_record(spec: EpisodeSpec, error: str, tb: str | None = None, *, retryable: bool = False) -> EpisodeRecord:
    """The record of an episode that raised or whose worker died: a failure with its (redacted) error.

    ``retryable`` marks a transient cause (worker death, LLM transport) that ``--retry-errors`` re-runs.
    """
    return EpisodeRecord.for_spec(
        spec, error=redact(error), error_kind="crash", traceback=redact(tb) if tb else None, retryable=retryable
    )


def execute_episode(fn_path: str, spec: EpisodeSpec, run_dir: str) -> EpisodeRecord:
    """Run one episode; an exception becomes an error record. Idempotent: writes only its own dir."""
    out_dir = episode_dir(Path(run_dir), spec)
    start = time.perf_counter()
    try:
        move_aside_other_episode(out_dir, spec)
        out_dir.mkdir(parents=True, exist_ok=True)
        record = resolve_episode_fn(fn_path)(spec, out_dir=out_dir)
        if not isinstance(record, EpisodeRecord):
            raise TypeError(f"episode function returned {type(record).__name__}, not EpisodeRecord")
        return record
    except Exception as e:  # noqa: BLE001 - any episode failure is recorded, the run goes on
        rec = error_record(spec, f"{type(e).__name__}: {e}", traceback.format_exc())
        return rec.model_copy(update={"timings": {"total": time.perf_counter() - start}})


def move_aside_other_episode(out_dir: Path, spec: EpisodeSpec) -> None:
    """Before ``spec``'s episode clears ``out_dir``: when the folder holds a finished episode of other settings
    (a run written before a setting was part of folder names, such as ``--sensing``, resumed with
    ``--allow-mixed``), move it to the folder today's layout names for it, where the report looks first, so
    that no result already written is lost. An unreadable record is left to be replaced, as before."""
    old = folder_record(out_dir)
    if old is None or of_spec(old, spec):
        return
    own = episode_dir(out_dir.parents[1], old)
    target, n = own, 0
    while target.exists():
        n += 1
        target = own.with_name(f"{own.name}__earlier{n}")
    out_dir.rename(target)
