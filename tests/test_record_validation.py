"""The record validator and the path-safety helper: numbers that cannot be, schema versions, symlinks,
bounded reads, writes that a full disk cannot leave half done."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from more_agent.record_validation import BadRecord, parse_record, record_json
from more_agent.records import RECORD_SCHEMA_VERSION, EpisodeRecord
from more_agent.safe_files import UnsafePath, append_text, open_nofollow, read_bounded, write_atomic

GOOD = {"task": "t", "scene": "s", "seed": 0, "planner": "oracle", "task_progress": 0.5}


def _text(**fields: object) -> str:
    return json.dumps({**GOOD, **fields})


def test_a_valid_record_round_trips() -> None:
    record = parse_record(_text(), source="x")
    assert record.task_progress == 0.5 and parse_record(record_json(record), source="x") == record


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"task_progress": 5.0}, "task_progress 5.0 is not in"),
        ({"task_progress": -0.1}, "task_progress -0.1 is not in"),
        ({"llm_usage": {"cost_usd": -752.52}}, "cost_usd -752.52"),
        ({"llm_usage": {"prompt_tokens": -5}}, "prompt_tokens -5 is not a count"),
        ({"llm_usage": {"completion_tokens": 10**15}}, "completion_tokens"),
        ({"high_level_steps": -1}, "high_level_steps"),
        ({"timings": {"total": 1e309}}, "not a number"),  # JSON's overflow to inf
        ({"schema_version": RECORD_SCHEMA_VERSION + 1}, "newer than this more-agent reads"),
        ({"schema_version": 1}, "older than .* cannot be migrated"),
        ({"schema_version": "2"}, "not a version number"),
    ],
)
def test_numbers_and_versions_that_cannot_be_are_refused(fields: dict[str, object], message: str) -> None:
    with pytest.raises(BadRecord, match=message):
        parse_record(_text(**fields), source="runs/x/episodes.jsonl")


@pytest.mark.parametrize("text", ['{"task_progress": NaN}', '{"task_progress": Infinity}', "[" * 100_000, '{"task": '])
def test_nan_deep_nesting_and_torn_json_are_one_error(text: str) -> None:
    with pytest.raises(BadRecord, match="runs/x"):
        parse_record(text, source="runs/x")


def test_an_older_version_is_migrated_when_a_migration_exists(monkeypatch: pytest.MonkeyPatch) -> None:
    from more_agent import record_validation

    old = RECORD_SCHEMA_VERSION - 1
    monkeypatch.setitem(record_validation.MIGRATIONS, old, lambda d: {**d, "task": d["task"].upper()})
    assert parse_record(_text(schema_version=old), source="x").task == "T"


def test_record_json_masks_secrets_in_every_string() -> None:
    record = EpisodeRecord(task="t", scene="s", seed=0, planner="more", llm="openai:m", error="key sk-abcdefgh12345678")
    assert "abcdefgh" not in record_json(record) and "***" in record_json(record, indent=2)


def test_write_atomic_replaces_a_symlink_not_its_target(tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / "summary.md").symlink_to(victim)
    write_atomic(tmp_path / "summary.md", "new")
    assert victim.read_text() == "precious" and not (tmp_path / "summary.md").is_symlink()
    assert (tmp_path / "summary.md").read_text() == "new"


def test_a_write_that_fails_leaves_the_old_file_and_no_temporary(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "episode.json"
    path.write_text("old")

    def full(fd: int, data: object) -> int:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "write", full)
    with pytest.raises(OSError, match="No space"):
        write_atomic(path, "new")
    monkeypatch.undo()
    assert path.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["episode.json"]


def test_appends_and_locks_never_follow_a_symlink(tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / "timeline.jsonl").symlink_to(victim)
    (tmp_path / ".lock").symlink_to(victim)
    with pytest.raises(UnsafePath, match="symlink"):
        append_text(tmp_path / "timeline.jsonl", "x\n")
    with pytest.raises(UnsafePath, match="symlink"):
        open_nofollow(tmp_path / ".lock", os.O_RDWR | os.O_CREAT)
    assert victim.read_text() == "precious"


def test_reads_are_bounded_and_drop_a_byte_order_mark(tmp_path: Path) -> None:
    with pytest.raises(UnsafePath, match="not a regular file"):
        read_bounded(Path("/dev/zero"), what="LLM config")
    big = tmp_path / "big.txt"
    big.write_bytes(b"x" * 101)
    with pytest.raises(UnsafePath, match="larger than 100 bytes"):
        read_bounded(big, what="task file", max_bytes=100)
    (tmp_path / "bom.txt").write_bytes(b"\xef\xbb\xbfputting_shopping_away\n")
    assert read_bounded(tmp_path / "bom.txt", what="task file") == "putting_shopping_away\n"
    with pytest.raises(UnsafePath, match="too long"):
        read_bounded(tmp_path / ("x" * 300), what="task file")
