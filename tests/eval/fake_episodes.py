"""Small deterministic episode functions for harness tests (importable by spawned workers)."""

from __future__ import annotations

import os
import time
import zlib
from pathlib import Path

from more_agent.records import ActionRecord, EpisodeRecord, EpisodeSpec, GoalCondition, LLMUsage


def deterministic_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """An outcome that depends only on (task, seed, planner): 3 goal conditions, some met, some seen."""
    h = zlib.crc32(f"{spec.task}|{spec.seed}|{spec.planner}".encode())
    met = [bool(h >> k & 1) for k in range(3)]
    seen = [f"obj_{k}" for k in range(3) if h >> (k + 3) & 1]
    conds = [
        GoalCondition(text=f"(ontop obj_{k} table_1)", satisfied=met[k], objects=[f"obj_{k}", "table_1"])
        for k in range(3)
    ]
    all_met = all(met)
    done = bool(h >> 6 & 1)
    return EpisodeRecord(
        task=spec.task,
        scene=spec.scene or "Rs_int",
        seed=spec.seed,
        planner=spec.planner,
        llm=spec.llm,
        description=f"do {spec.task}",
        success=all_met and done,
        all_goals_met=all_met,
        done_called=done,
        task_progress=sum(met) / 3,
        goal_conditions=conds,
        observed_objects=[*seen, "table_1"],
        high_level_steps=2,
        actions=[
            ActionRecord(step=0, name="navigate", arguments=["table_1"], ok=True),
            ActionRecord(step=1, name="grasp", arguments=["obj_0"], ok=met[0], feedback="" if met[0] else "hand full"),
        ],
        trajectory=[(0.0, 0.0), (1.0, 0.5 * (h % 5)), (2.0, 1.0)],
        llm_usage=LLMUsage(calls=2, prompt_tokens=100, completion_tokens=20, cost_usd=0.001),
    )


def slow_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """``deterministic_episode`` after a short sleep (for kill-and-resume tests and benchmarks)."""
    time.sleep(float(os.environ.get("FAKE_EPISODE_SECONDS", "0.15")))
    return deterministic_episode(spec, out_dir=out_dir)


def raising_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """Raises for tasks whose name contains 'bad', else ``deterministic_episode``."""
    if "bad" in spec.task:
        raise RuntimeError(f"simulated failure in {spec.task}")
    return deterministic_episode(spec, out_dir=out_dir)


def dying_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """Kills its own worker process for tasks named 'die', else ``deterministic_episode``."""
    if spec.task == "die":
        os._exit(3)
    return deterministic_episode(spec, out_dir=out_dir)


def limited_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """Holds the worker's LLM limiter for 0.2 s while counting holders via marker files.

    The record's ``timings['holders']`` is the most holders seen at once (1 when the limit is 1).
    """
    from more_agent.llm.concurrency import llm_limiter

    assert out_dir is not None
    marks = out_dir.parent / "_llm_marks"
    marks.mkdir(exist_ok=True)
    mine = marks / out_dir.name
    with llm_limiter():
        mine.touch()
        holders = len(list(marks.iterdir()))
        time.sleep(0.2)
        holders = max(holders, len(list(marks.iterdir())))
        mine.unlink()
    rec = deterministic_episode(spec, out_dir=out_dir)
    return rec.model_copy(update={"timings": {"holders": float(holders)}})


def flaky_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """A retryable LLM error for tasks named 'flaky*' while ``FAKE_LLM_DOWN`` is set, else ``deterministic_episode``."""
    if spec.task.startswith("flaky") and os.environ.get("FAKE_LLM_DOWN"):
        return EpisodeRecord.for_spec(spec, error="LLM error (LLMServerError): 500 on every attempt", error_kind="llm",
                                     retryable=True)
    return deterministic_episode(spec, out_dir=out_dir)


def swallowing_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """Sleeps and turns a KeyboardInterrupt into another exception, as native callbacks (numba) can."""
    try:
        time.sleep(float(os.environ.get("FAKE_EPISODE_SECONDS", "0.15")))
    except KeyboardInterrupt:
        raise RuntimeError("error in a native callback") from None
    return deterministic_episode(spec, out_dir=out_dir)


def remembering_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """``deterministic_episode`` of the spec's trial that fails in trial 0 of tasks named 'flaky*' (a retryable
    error), leaves one failure summary and shows the long-term memory it was given as its description."""
    if spec.task.startswith("flaky") and spec.trial == 0 and os.environ.get("FAKE_FLAKY") == "1":
        return EpisodeRecord.for_spec(spec, error="LLM error: timeout", error_kind="llm", retryable=True)
    record = deterministic_episode(spec, out_dir=out_dir)
    return record.model_copy(
        update={
            "trial": spec.trial,
            "long_term_memory": spec.long_term_memory,
            "description": " | ".join(spec.past_failures),
            "failure_summaries": [f"{spec.task} s{spec.seed} trial {spec.trial} failed"],
        }
    )


def folder_writing_episode(spec: EpisodeSpec, *, out_dir: Path | None = None) -> EpisodeRecord:
    """``deterministic_episode`` that, as the real runner does, clears its folder and writes its ``episode.json``."""
    from more_agent.eval.episode_folder import EpisodeFolder

    record = deterministic_episode(spec, out_dir=out_dir)
    if out_dir is not None:
        folder = EpisodeFolder(out_dir)
        folder.clear()
        folder.write_record(record)
    return record
