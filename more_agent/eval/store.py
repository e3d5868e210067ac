"""The results store of one evaluation run: ``DIR/episodes.jsonl``, ``DIR/run.json``, ``DIR/episodes/``.

``episodes.jsonl`` holds one ``EpisodeRecord`` JSON per line, appended by the single parent process
with flush + ``os.fsync`` per line, so a kill at any moment loses at most the episodes in flight and
at worst leaves one torn last line. ``read_records`` drops a torn last line (and with
``repair=True`` truncates the file to the last complete line); any other bad line is an error.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from types import TracebackType

from pydantic import BaseModel, Field, ValidationError

from more_agent.errors import UserError
from more_agent.eval.record import EpisodeRecord, EpisodeSpec

EPISODES_FILE = "episodes.jsonl"
RUN_FILE = "run.json"
EPISODE_DIRS = "episodes"


class RunConfig(BaseModel):
    """What a run evaluates; written to ``DIR/run.json``. Holds no secrets."""

    planner: str = Field(description="Planner name.")
    llm: str | None = Field(default=None, description="LLM spec with any credentials removed.")
    tasks: list[str] = Field(default_factory=list, description="Task names, in run order.")
    seeds: list[int] = Field(default_factory=list, description="Seeds run for every task.")
    scene: str | None = Field(default=None, description="Scene for every task; None lets each episode pick.")
    start: str = Field(default="random", description="Robot start of every episode: 'random', 'random-area' or 'task-room'.")
    episode_fn: str = Field(description="Dotted path of the episode function.")
    workers: int = Field(default=1, description="Local worker processes (ignored with Ray).")
    ray_address: str | None = Field(default=None, description="Ray cluster address, or None for processes.")
    more_agent_version: str = Field(default="", description="Package version that wrote the run.")


_SECRET = re.compile(r"(?i)(api[_-]?key|token|secret|password)=[^&;\s]*")


def redact(spec: str | None) -> str | None:
    """An LLM spec with any ``key=value`` credential replaced by ``key=***``."""
    return None if spec is None else _SECRET.sub(lambda m: f"{m.group(1)}=***", spec)


class TornStoreError(UserError):
    """``episodes.jsonl`` has an unreadable line that is not the last one."""


def _parse_lines(data: bytes, path: Path) -> tuple[list[EpisodeRecord], int]:
    """Records of complete lines and the byte length of the valid prefix; a bad last line is dropped."""
    records: list[EpisodeRecord] = []
    good_end = 0
    pos = 0
    while pos < len(data):
        nl = data.find(b"\n", pos)
        if nl < 0:
            break  # the writer ends every line with a newline: a last line without one is torn
        end = nl + 1
        line = data[pos:end].strip()
        if line:
            try:
                records.append(EpisodeRecord.model_validate_json(line))
            except ValidationError as e:
                if not data[end:].strip():
                    break  # garbled last line: drop it
                raise TornStoreError(f"{path}: unreadable record at byte {pos}: {e.errors()[0]['msg']}") from None
        good_end = end
        pos = end
    return records, good_end


def read_records(path: Path, *, repair: bool = False) -> list[EpisodeRecord]:
    """All records of an ``episodes.jsonl`` (or of ``DIR/episodes.jsonl`` when given a directory).

    A torn last line is ignored; with ``repair=True`` the file is truncated to its valid prefix.
    """
    path = Path(path)
    if path.is_dir():
        path = path / EPISODES_FILE
    if not path.exists():
        return []
    data = path.read_bytes()
    records, good_end = _parse_lines(data, path)
    if repair and good_end < len(data):
        with open(path, "r+b") as fh:
            fh.truncate(good_end)
            fh.flush()
            os.fsync(fh.fileno())
    return records


class EpisodeWriter:
    """Appends records to ``episodes.jsonl``, one durable line each (write, flush, fsync)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._fh = open(self.path, "ab")

    def append(self, record: EpisodeRecord) -> None:
        """Write one record as one line and make it durable before returning."""
        self._fh.write(record.model_dump_json().encode("utf-8") + b"\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        """Close the file."""
        self._fh.close()

    def __enter__(self) -> EpisodeWriter:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


def pending(specs: list[EpisodeSpec], records: list[EpisodeRecord]) -> list[EpisodeSpec]:
    """The specs with no record yet, in order."""
    done: dict[tuple[str, int, str], set[str]] = {}
    for r in records:
        done.setdefault((r.task, r.seed, r.planner), set()).add(r.scene)
    out = []
    for s in specs:
        scenes = done.get((s.task, s.seed, s.planner))
        if not scenes or (s.scene is not None and s.scene not in scenes):
            out.append(s)
    return out


def episode_dirname(task: str, scene: str | None, seed: int, planner: str) -> str:
    """Directory name (under ``DIR/episodes/``) for one episode's files; 'auto' for an unset scene."""
    raw = f"{task}__{scene or 'auto'}__s{seed}__{planner}"
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", raw)


def write_run_config(run_dir: Path, config: RunConfig) -> None:
    """Write ``DIR/run.json`` atomically (temp file + rename)."""
    tmp = run_dir / (RUN_FILE + ".tmp")
    tmp.write_text(config.model_dump_json(indent=2) + "\n", encoding="utf-8")
    os.replace(tmp, run_dir / RUN_FILE)


def read_run_config(run_dir: Path) -> RunConfig | None:
    """The run's configuration, or None if ``run.json`` is missing."""
    path = Path(run_dir) / RUN_FILE
    if not path.exists():
        return None
    try:
        return RunConfig.model_validate(json.loads(path.read_text(encoding="utf-8")))
    except (ValueError, ValidationError) as e:
        raise UserError(f"{path} is not a valid run configuration: {e}") from None


def prepare_run_dir(run_dir: Path, config: RunConfig, *, resume: bool) -> list[EpisodeRecord]:
    """Create or reopen a run directory and return the records already in it.

    Without ``resume`` a non-empty directory is refused. With ``resume`` the planner and LLM must
    match the stored ``run.json``; a torn last line is truncated.
    """
    run_dir = Path(run_dir)
    if run_dir.exists() and not run_dir.is_dir():
        raise UserError(f"{run_dir} exists and is not a directory")
    if run_dir.exists() and any(run_dir.iterdir()) and not resume:
        raise UserError(f"{run_dir} is not empty; pass --resume to continue that run, or choose another --out")
    run_dir.mkdir(parents=True, exist_ok=True)
    old = read_run_config(run_dir)
    if old is not None and (old.planner, old.llm) != (config.planner, config.llm):
        raise UserError(
            f"{run_dir} holds a run of planner={old.planner!r} llm={old.llm!r}; "
            f"cannot resume it with planner={config.planner!r} llm={config.llm!r}"
        )
    records = read_records(run_dir / EPISODES_FILE, repair=True)
    write_run_config(run_dir, config)
    return records
