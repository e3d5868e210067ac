"""The results store of one evaluation run: ``DIR/episodes.jsonl``, ``DIR/run.json``, ``DIR/episodes/``.

``episodes.jsonl`` holds one ``EpisodeRecord`` JSON per line, appended by the single parent process
with flush + ``os.fsync`` per line, so a kill at any moment loses at most the episodes in flight and
at worst leaves one torn last line. ``read_records`` drops a torn last line (and with
``repair=True`` truncates the file to the last complete line); any other bad line is an error.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import re
from collections.abc import Iterable
from pathlib import Path
from types import TracebackType

from pydantic import BaseModel, Field, ValidationError

from more_agent.errors import UserError, check_writable_dir
from more_agent.eval.runlock import LOCK_FILE
from more_agent.record_validation import BadRecord, parse_record, record_json
from more_agent.records import (
    DEFAULT_HISTORY,
    EPISODE_SETTINGS,
    GT_PERCEPTION,
    LEGACY_DESCRIPTIONS,
    EpisodeRecord,
    EpisodeSpec,
    HistoryMode,
    episode_settings,
    legacy_history,
)
from more_agent.redaction import redact_tree
from more_agent.safe_files import open_nofollow, read_bounded, write_atomic
from more_agent.sensing_spec import DEFAULT_SENSING, LEGACY_SENSING

EPISODES_FILE = "episodes.jsonl"
RETRIED_FILE = "retried.jsonl"
"""Error records that ``--retry-errors`` replaced, kept for the record (not part of the results)."""
RUN_FILE = "run.json"
EPISODE_DIRS = "episodes"
MAX_STORE_BYTES = 2 * 1024**3
"""Largest ``episodes.jsonl`` read (about a million episodes)."""


class RunConfig(BaseModel):
    """What a run evaluates; written to ``DIR/run.json``. Holds no secrets."""

    planner: str = Field(description="Planner name.")
    llm: str | None = Field(default=None, description="LLM spec with any credentials removed.")
    tasks: list[str] = Field(default_factory=list, description="Task names, in run order.")
    seeds: list[int] = Field(default_factory=list, description="Seeds run for every task.")
    scene: str | None = Field(default=None, description="Scene for every task; None lets each episode pick.")
    start: str = Field(
        default="random", description="Robot start of every episode: 'random', 'random-area' or 'task-room'."
    )
    distractors: bool = Field(
        default=True, description="Whether every episode's world holds the scene's own small objects."
    )
    descriptions: str = Field(
        default="named", description="Description mode of every episode: 'named' or 'paper' (sim.descriptions)."
    )
    history: HistoryMode = Field(default=DEFAULT_HISTORY, description="Action history shown to LLM and VLM planners.")
    perception: str = Field(
        default=GT_PERCEPTION, description="Perception mode of every episode: 'gt' or 'noisy[:KEY=VALUE,...]'."
    )
    sensing: str = Field(
        default=DEFAULT_SENSING, description="Sensing cadence of every episode: 'DISTANCEm/ANGLEdeg' (--sensing)."
    )
    trials: int = Field(default=1, ge=1, description="Trials of every (task, seed) world, run in sequence.")
    long_term_memory: bool = Field(
        default=False,
        description="Give each trial the failure summaries its world's earlier trials left (BUMBLE's --add_past).",
    )
    episode_fn: str = Field(description="Dotted path of the episode function.")
    workers: int = Field(default=1, description="Local worker processes (ignored with Ray).")
    ray_address: str | None = Field(default=None, description="Ray cluster address, or None for processes.")
    more_agent_version: str = Field(default="", description="Package version that wrote the run.")
    earlier: list[dict[str, object]] = Field(
        default_factory=list,
        description="The settings (MIXING_FIELDS) of earlier runs whose episodes --allow-mixed kept in this folder.",
    )


MIXING_FIELDS = ("planner", "tasks", "seeds", "scene", *EPISODE_SETTINGS, "trials", "episode_fn")
"""What a resumed run must share with the run already in its folder (unless mixing is allowed)."""


def _comparable(config: RunConfig) -> dict[str, object]:
    """The mixing fields of ``config``, task and seed lists as sets."""
    values = config.model_dump(include=set(MIXING_FIELDS))
    return {**values, "tasks": set(config.tasks), "seeds": set(config.seeds)}


def _config_of_records(records: list[EpisodeRecord], config: RunConfig) -> RunConfig:
    """The run configuration ``records`` imply, for a folder whose ``run.json`` is missing."""
    llms = sorted({str(r.llm) for r in records})

    def joined(name: str, sep: str = ",") -> str:
        values = sorted({str(getattr(r, name)) for r in records})
        return values[0] if len(values) == 1 else sep.join(values)

    return config.model_copy(
        update={
            **{name: joined(name) for name in ("planner", "start", "history", "descriptions", "sensing")},
            "perception": joined("perception", ";"),  # its text holds commas
            "llm": records[0].llm if len(llms) == 1 else ",".join(llms),
            "tasks": sorted({r.task for r in records} | set(config.tasks)),
            "seeds": sorted({r.seed for r in records} | set(config.seeds)),
            "trials": max(config.trials, 1 + max(r.trial for r in records)),
            "long_term_memory": any(r.long_term_memory for r in records),
        }
    )


def check_same_run(run_dir: Path, old: RunConfig, new: RunConfig) -> None:
    """Raise a UserError naming every field in which ``new`` differs from the run already in ``run_dir``."""
    a, b = _comparable(old), _comparable(new)
    diffs = [f"{f}: {_show(a[f])} -> {_show(b[f])}" for f in MIXING_FIELDS if a[f] != b[f]]
    if diffs:
        raise UserError(
            f"{run_dir} holds another run ({'; '.join(diffs)}); cannot resume it with these settings "
            "(pass --allow-mixed to mix them in one folder, or choose another --out)"
        )


def _show(value: object) -> str:
    """A short form of a config value for messages."""
    text = ",".join(map(str, sorted(value))) if isinstance(value, set) else repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


class TornStoreError(UserError):
    """``episodes.jsonl`` has an unreadable line that is not the last one."""


def _parse_lines(data: bytes, path: Path) -> tuple[list[EpisodeRecord], int]:
    """Records of complete lines and the byte length of the valid prefix; a last line that is not JSON
    (torn by a kill) is dropped. A record that is JSON but not a valid record is an error wherever it is:
    dropping it would lose an episode someone edited."""
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
            if not data[end:].strip() and not _is_json(line):
                break  # garbled last line: drop it
            try:
                records.append(parse_record(line, source=f"{path}: unreadable record at byte {pos}"))
            except BadRecord as e:
                raise TornStoreError(str(e)) from None
        good_end = end
        pos = end
    return records, good_end


def _is_json(line: bytes) -> bool:
    try:
        json.loads(line)
    except (ValueError, RecursionError):
        return False
    return True


def read_records(path: Path, *, repair: bool = False) -> list[EpisodeRecord]:
    """All records of an ``episodes.jsonl`` (or of ``DIR/episodes.jsonl`` when given a directory).

    A torn last line is ignored; with ``repair=True`` the file is truncated to its valid prefix.
    """
    path = Path(path)
    if path.is_dir():
        path = path / EPISODES_FILE
    if not path.exists():
        return []
    data = read_bounded(path, what="run records", max_bytes=MAX_STORE_BYTES).encode("utf-8")
    records, good_end = _parse_lines(data, path)
    if repair and good_end < len(data):
        fd = open_nofollow(path, os.O_RDWR)  # never truncate a symlink's target
        try:
            os.ftruncate(fd, good_end)
            os.fsync(fd)
        finally:
            os.close(fd)
    return records


class EpisodeWriter:
    """Appends records to ``episodes.jsonl``, one durable line each (write, flush, fsync)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._fh = os.fdopen(open_nofollow(self.path, os.O_WRONLY | os.O_CREAT | os.O_APPEND), "ab")

    def append(self, record: EpisodeRecord) -> None:
        """Write one record as one line and make it durable before returning."""
        self._fh.write(record_json(record).encode("utf-8") + b"\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def truncate(self) -> None:
        """Empty the file."""
        self._fh.truncate(0)

    def close(self) -> None:
        """Close the file."""
        self._fh.close()

    def __enter__(self) -> EpisodeWriter:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


def retire_retryable(run_dir: Path, records: list[EpisodeRecord]) -> list[EpisodeRecord]:
    """Move the retryable error records of ``run_dir`` to ``retried.jsonl``; return the records kept.

    The retired records are appended (durably) to ``retried.jsonl`` before ``episodes.jsonl`` is
    atomically replaced by the kept ones, so a crash at any point loses no record: at worst a
    retired record is in both files, and the episode is simply re-run.
    """
    retired = [r for r in records if r.retryable]
    if not retired:
        return records
    kept = [r for r in records if not r.retryable]
    with EpisodeWriter(run_dir / RETRIED_FILE) as log:
        for r in retired:
            log.append(r)
    tmp = run_dir / (EPISODES_FILE + ".tmp")
    with EpisodeWriter(tmp) as writer:
        writer.truncate()
        for r in kept:
            writer.append(r)
    os.replace(tmp, run_dir / EPISODES_FILE)
    return kept


RecordIndex = dict[tuple[object, ...], list[EpisodeRecord]]
"""Records grouped by what they share with their spec (:func:`index_records`, :func:`recorded`)."""


def index_records(records: Iterable[EpisodeRecord]) -> RecordIndex:
    """``records`` grouped for :func:`recorded`, so matching specs to records is not quadratic."""
    index: RecordIndex = {}
    for r in records:
        index.setdefault(_match_key(r), []).append(r)
    return index


def recorded(spec: EpisodeSpec, index: RecordIndex) -> EpisodeRecord | None:
    """The record of ``spec`` in ``index`` (the first that is :func:`of_spec`), or None."""
    return next((r for r in index.get(_match_key(spec), []) if of_spec(r, spec)), None)


def pending(specs: list[EpisodeSpec], records: list[EpisodeRecord]) -> list[EpisodeSpec]:
    """The specs with no record yet, in order (a record counts for a spec when it is :func:`of_spec`)."""
    index = index_records(records)
    return [s for s in specs if recorded(s, index) is None]


def of_spec(record: EpisodeRecord, spec: EpisodeSpec, *, trial: bool = True) -> bool:
    """Whether ``record`` is an episode of ``spec``: same task, seed, planner, LLM, start, description mode,
    history, perception, sensing cadence, memory, distractors (a record that predates the distractors field
    matches either) and scene (a record of a scene file's scene counts for the file); and, unless ``trial`` is
    False, the same trial."""
    if _match_key(record) != _match_key(spec) or (trial and record.trial != spec.trial):
        return False
    if record.distractors not in (None, spec.distractors):
        return False
    return spec.scene is None or record.scene in {spec.scene, _scene_name(spec.scene)}


def _match_key(x: EpisodeRecord | EpisodeSpec) -> tuple[object, ...]:
    """What a record shares with its spec beside scene, distractors and trial (:func:`of_spec`)."""
    return (x.task, x.seed, x.planner, *(getattr(x, name) for name in EPISODE_SETTINGS if name != "distractors"))


def with_past_failures(spec: EpisodeSpec, records: list[EpisodeRecord]) -> EpisodeSpec | None:
    """``spec`` given the long-term memory its world's earlier trials left in ``records`` (the failure
    summaries of trials 0 .. spec.trial - 1, in trial order); None while one of those trials has no
    result yet (no record, or a retryable error that ``--retry-errors`` will run again). Without
    ``long_term_memory`` (or for trial 0) ``spec`` as it is."""
    if not spec.long_term_memory or spec.trial == 0:
        return spec
    earlier = {r.trial: r for r in records if r.trial < spec.trial and of_spec(r, spec, trial=False)}
    if len(earlier) < spec.trial or any(r.retryable for r in earlier.values()):
        return None
    past = tuple(s for t in sorted(earlier) for s in earlier[t].failure_summaries)
    return spec.model_copy(update={"past_failures": past})


@functools.cache
def _scene_name(scene: str) -> str:
    """The name a record gives the scene ``scene``: the ``name`` inside a scene file, else ``scene`` itself."""
    if not scene.endswith(".json"):
        return scene
    from more_agent.sim.scene import load_scene

    try:
        return load_scene(scene).name
    except UserError:
        return scene


def episode_dirname(
    task: str,
    scene: str | None,
    seed: int,
    planner: str,
    *,
    llm: str | None = None,
    start: str = "random",
    distractors: bool | None = True,
    descriptions: str = "named",
    history: str = "paper",
    perception: str = "gt",
    sensing: str = DEFAULT_SENSING,
    long_term_memory: bool = False,
    trial: int = 0,
) -> str:
    """Directory name (under ``DIR/episodes/``) for one episode's files; 'auto' for an unset scene.

    The LLM, a start other than 'random', ``--no-distractors``, a description mode other than 'named' and
    a history other than 'paper', a perception other than 'gt', a sensing cadence other than the default and the
    long-term memory are part of the name, so that the episodes of two settings mixed in one folder
    (``--allow-mixed``) never share, or clear, a folder; so is a trial other than the first (``t1`` is the second).
    """
    parts = [task, scene or "auto", f"s{seed}" + (f"t{trial}" if trial else ""), planner]
    if llm is not None:
        parts.append(llm if len(llm) <= 60 else f"{llm[:40]}-{hashlib.sha256(llm.encode()).hexdigest()[:8]}")
    if start != "random":
        parts.append(start)
    if distractors is False:
        parts.append("nodistractors")
    if descriptions != "named":
        parts.append(f"{descriptions}-descriptions")
    if history != "paper":
        parts.append(f"{history}-history")
    if perception != "gt":
        parts.append(perception_part(perception))
    if sensing != DEFAULT_SENSING:
        parts.append(sensing_part(sensing))
    if long_term_memory:
        parts.append("memory")
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", "__".join(parts))


def perception_part(perception: str) -> str:
    """The perception mode's part of an episode folder name: the canonical text, hashed when long."""
    text = perception.replace(":", "-").replace("=", "").replace(",", "-")
    return text if len(text) <= 60 else f"noisy-{hashlib.sha256(perception.encode()).hexdigest()[:12]}"


def sensing_part(sensing: str) -> str:
    """The sensing cadence's part of a folder name: 'sensing-0.5m-30deg'."""
    return f"sensing-{sensing.replace('/', '-')}"


def episode_dir(run_dir: Path, episode: EpisodeSpec | EpisodeRecord, scene: str | None = None) -> Path:
    """The folder of ``episode``'s files in the run folder ``run_dir`` (``scene`` in place of its own)."""
    name = episode_dirname(
        episode.task,
        scene if scene is not None else episode.scene,
        episode.seed,
        episode.planner,
        trial=episode.trial,
        **episode_settings(episode),
    )
    return Path(run_dir) / EPISODE_DIRS / name


def write_run_config(run_dir: Path, config: RunConfig) -> None:
    """Write ``DIR/run.json`` atomically (temp file + rename)."""
    write_atomic(run_dir / RUN_FILE, json.dumps(redact_tree(config.model_dump(mode="json")), indent=2) + "\n")


def read_run_config(run_dir: Path) -> RunConfig | None:
    """The run's configuration, or None if ``run.json`` is missing. A ``run.json`` written before the
    history option gets the history its episodes ran with (:func:`~more_agent.records.legacy_history`), one
    written before the sensing option the cadence of those versions."""
    path = Path(run_dir) / RUN_FILE
    if not path.exists():
        return None
    try:
        data = json.loads(read_bounded(path, what="run configuration"))
        if isinstance(data, dict) and "history" not in data:
            data = legacy_history(data)
        if isinstance(data, dict) and "descriptions" not in data:
            data = {**data, "descriptions": LEGACY_DESCRIPTIONS}
        if isinstance(data, dict) and "sensing" not in data:
            data = {**data, "sensing": LEGACY_SENSING}
        return RunConfig.model_validate(data)
    except (ValueError, ValidationError, RecursionError) as e:
        raise UserError(f"{path} is not a valid run configuration: {e}") from None


def check_run_dir(run_dir: Path) -> None:
    """Raise a UserError unless ``run_dir`` is (or can become) a writable run folder."""
    check_writable_dir(run_dir)
    for name in (EPISODES_FILE, RUN_FILE):
        if (run_dir / name).exists() and not (run_dir / name).is_file():
            raise UserError(f"{run_dir / name} exists and is not a file")


def prepare_run_dir(
    run_dir: Path, config: RunConfig, *, resume: bool, allow_mixed: bool = False
) -> list[EpisodeRecord]:
    """Create or reopen a run directory and return the records already in it.

    Without ``resume`` a non-empty directory is refused. With ``resume`` the planner, LLM, tasks,
    seeds, scene, start mode, distractors, history and episode function must match the stored
    ``run.json`` (or, when it is missing, the records), unless ``allow_mixed``; a torn last line is truncated.
    """
    run_dir = Path(run_dir)
    check_run_dir(run_dir)
    if run_dir.exists() and any(p.name != LOCK_FILE for p in run_dir.iterdir()) and not resume:
        raise UserError(f"{run_dir} is not empty; pass --resume to continue that run, or choose another --out")
    run_dir.mkdir(parents=True, exist_ok=True)
    records = read_records(run_dir / EPISODES_FILE)
    old = read_run_config(run_dir) or (_config_of_records(records, config) if records else None)
    if old is not None and not allow_mixed:
        check_same_run(run_dir, old, config)
    if old is not None and _comparable(old) != _comparable(config):  # mixed: run.json says what else is here
        earlier = [*old.earlier, old.model_dump(include=set(MIXING_FIELDS))]
        config = config.model_copy(update={"earlier": earlier})
    records = read_records(run_dir / EPISODES_FILE, repair=True)
    write_run_config(run_dir, config)
    return records
