"""The one record validator: an episode record read back from disk is checked before anyone uses it.

A record is a file anyone can edit, and a server once sent negative token counts. Reports average
``task_progress``; a 5.0 there would print TP 133 %, a NaN would print ``nan``. So every record read
(``episodes.jsonl``, ``episode.json``) passes :func:`parse_record`: known schema version (older ones
migrated where :data:`MIGRATIONS` knows how, else refused saying which version and why; newer ones
refused), no NaN or infinity anywhere, fractions in [0, 1], counts non-negative and bounded, cost
never negative. A bad record is a :class:`BadRecord` (a UserError: one line, exit status 2).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from typing import Any

from pydantic import ValidationError

from more_agent.errors import UserError
from more_agent.records import RECORD_SCHEMA_VERSION, UPGRADES, EpisodeRecord
from more_agent.redaction import redact_tree

MAX_COUNT = 10**12
"""Largest token, call, step or byte count a record may hold (a trillion tokens is about $2.5M of gpt-4o)."""

MAX_COST_USD = 1e9
"""Largest cost a record may hold."""

MIGRATIONS: Mapping[int, Callable[[dict[str, Any]], dict[str, Any]]] = UPGRADES
"""Older schema version -> function that turns such a record into the next version's form. A version
missing here is refused with a message (no migration for schema 1 exists: its records predate this
repository's first release)."""


class BadRecord(UserError):
    """A record read from disk is not one this version can trust."""


def parse_record(text: str | bytes, *, source: str) -> EpisodeRecord:
    """The validated record in the JSON ``text`` read from ``source`` (named in errors)."""
    try:
        data = json.loads(text, parse_constant=_refuse_constant)
    except (ValueError, RecursionError) as e:
        raise BadRecord(f"{source}: not a JSON record ({_first_line(e)})") from None
    if not isinstance(data, dict):
        raise BadRecord(f"{source}: not a JSON object")
    data = migrate(data, source=source)
    try:
        record = EpisodeRecord.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        raise BadRecord(f"{source}: {'.'.join(map(str, err['loc']))}: {err['msg']}") from None
    check_record(record, source=source)
    return record


def record_json(record: EpisodeRecord, *, indent: int | None = None) -> str:
    """The JSON text of ``record`` as it is written to disk, every string redacted (one line without ``indent``)."""
    separators = (",", ":") if indent is None else (",", ": ")
    return json.dumps(
        redact_tree(record.model_dump(mode="json")), indent=indent, separators=separators, ensure_ascii=False
    )


def _refuse_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number a record may hold")


def _first_line(e: BaseException) -> str:
    return (str(e) or type(e).__name__).splitlines()[0][:200]


def migrate(data: dict[str, Any], *, source: str) -> dict[str, Any]:
    """``data`` in the current schema: older versions migrated step by step, unknown ones refused."""
    version = data.get("schema_version", RECORD_SCHEMA_VERSION)
    if not isinstance(version, int) or isinstance(version, bool):
        raise BadRecord(f"{source}: schema_version {version!r} is not a version number")
    if version > RECORD_SCHEMA_VERSION:
        raise BadRecord(
            f"{source}: record schema {version} is newer than this more-agent reads ({RECORD_SCHEMA_VERSION}); "
            "upgrade more-agent to read it"
        )
    while version < RECORD_SCHEMA_VERSION:
        step = MIGRATIONS.get(version)
        if step is None:
            raise BadRecord(
                f"{source}: record schema {version} is older than {RECORD_SCHEMA_VERSION} and cannot be migrated "
                "(its metrics are not comparable); re-run those episodes"
            )
        data, version = step(data), version + 1
    return {**data, "schema_version": version}


def check_record(record: EpisodeRecord, *, source: str) -> None:
    """Raise BadRecord for a number the record cannot hold (NaN, a fraction outside [0, 1], a negative count)."""
    problems = list(_number_problems(record.model_dump(), ""))
    if not 0.0 <= record.task_progress <= 1.0:
        problems.append(f"task_progress {record.task_progress} is not in [0, 1]")
    if record.llm_usage.cost_usd < 0 or record.llm_usage.cost_usd > MAX_COST_USD:
        problems.append(f"llm_usage.cost_usd {record.llm_usage.cost_usd} is not in [0, {MAX_COST_USD:g}]")
    if problems:
        raise BadRecord(f"{source}: {problems[0]}")


_COUNTS = frozenset(
    {
        "seed",
        "high_level_steps",
        "low_level_steps",
        "step",
        "calls",
        "prompt_tokens",
        "completion_tokens",
        "cache_hits",
        "images",
        "image_bytes",
        "image_tokens",
        "reasoning_tokens",
        "objects",
        "task_objects",
        "distractors",
    }
)
"""Integer fields of a record (at any depth) that count something: 0 .. MAX_COUNT."""


def _number_problems(value: object, where: str) -> list[str]:
    """Every NaN or infinity in ``value``, and every count out of range, as 'path: why'."""
    if isinstance(value, dict):
        return [p for k, v in value.items() for p in _number_problems(v, f"{where}.{k}" if where else str(k))]
    if isinstance(value, (list, tuple)):
        return [p for i, v in enumerate(value) for p in _number_problems(v, f"{where}[{i}]")]
    if isinstance(value, float) and not math.isfinite(value):
        return [f"{where} is {value}, not a number"]
    if isinstance(value, int) and not isinstance(value, bool) and where.rsplit(".", 1)[-1] in _COUNTS:
        if not 0 <= value <= MAX_COUNT:
            return [f"{where} {value} is not a count in [0, {MAX_COUNT}]"]
    return []
