"""The harness: task expansion, failing and dying episodes, process pool, LLM limit, kill -9 + resume."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

from more_agent.errors import UserError
from more_agent.eval.harness import config_specs, evaluate, resolve_tasks
from more_agent.eval.store import RunConfig, episode_dir, read_records
from more_agent.eval.worker import resolve_episode_fn
from more_agent.records import EpisodeRecord
from tests.eval import fake_episodes

REPO = Path(__file__).resolve().parents[2]
FAKE = "tests.eval.fake_episodes"


def config(fn: str, tasks: list[str], seeds: int = 1, workers: int = 1) -> RunConfig:
    return RunConfig(planner="oracle", tasks=tasks, seeds=list(range(seeds)), episode_fn=f"{FAKE}:{fn}", workers=workers)


def outcome(records: list[EpisodeRecord]) -> list[str]:
    """Records without timings/tracebacks, sorted: what must not depend on how episodes were run."""
    return sorted(r.model_copy(update={"timings": {}, "traceback": None}).model_dump_json() for r in records)


def test_resolve_tasks_names_files_and_sets(tmp_path: Path) -> None:
    assert resolve_tasks(" a, b ,a,,c") == ["a", "b", "c"]
    lines = tmp_path / "tasks.txt"
    lines.write_text("# comment\nx\n\ny\n")
    assert resolve_tasks(str(lines)) == ["x", "y"]
    js = tmp_path / "tasks.json"
    js.write_text('["p", "q"]')
    assert resolve_tasks(str(js)) == ["p", "q"]
    assert resolve_tasks("more-paper", task_set=lambda name: [name + "-1", name + "-2"]) == ["more-paper-1", "more-paper-2"]
    js.write_text('["p", 3]')
    with pytest.raises(UserError, match="JSON list"):
        resolve_tasks(str(js))
    with pytest.raises(UserError, match="does not exist"):
        resolve_tasks(str(tmp_path / "nope.txt"))
    with pytest.raises(UserError, match="names no task"):
        resolve_tasks(" , ")


def test_specs_and_episode_fn_resolution() -> None:
    specs = config_specs(config("deterministic_episode", ["a", "b"], seeds=2))
    assert [(s.task, s.seed) for s in specs] == [("a", 0), ("a", 1), ("b", 0), ("b", 1)]
    assert resolve_episode_fn(f"{FAKE}.slow_episode") is fake_episodes.slow_episode
    with pytest.raises(UserError, match="cannot import"):
        resolve_episode_fn("no_such_module:fn")


def test_raising_episode_is_recorded_and_run_finishes(tmp_path: Path) -> None:
    records = evaluate(config("raising_episode", ["a", "bad", "c"], seeds=2), tmp_path / "run", show_progress=False)
    assert len(records) == 6 == len(read_records(tmp_path / "run"))
    bad = [r for r in records if r.task == "bad"]
    assert all(r.error == "RuntimeError: simulated failure in bad" for r in bad)
    assert all("raise RuntimeError" in (r.traceback or "") for r in bad)
    assert all(r.error is None for r in records if r.task != "bad")


@pytest.mark.slow
def test_process_pool_matches_inline_and_survives_dying_workers(tmp_path: Path) -> None:
    tasks = ["a", "die", "b", "c"]
    inline = evaluate(config("dying_episode", ["a", "b", "c"], seeds=2), tmp_path / "inline", show_progress=False)
    pooled = evaluate(config("dying_episode", tasks, seeds=2, workers=2), tmp_path / "pool", show_progress=False)
    died = [r for r in pooled if r.task == "die"]
    assert len(died) == 2 and all(r.error and r.error.startswith("WorkerDied") for r in died)
    assert outcome([r for r in pooled if r.task != "die"]) == outcome(inline)
    assert Counter(r.key() for r in read_records(tmp_path / "pool")).most_common(1)[0][1] == 1


def test_a_death_is_charged_only_to_the_episode_that_died(tmp_path: Path) -> None:
    tasks = ["a", "die", "b", "c", "d"]
    pooled = evaluate(config("dying_episode", tasks, seeds=2, workers=2), tmp_path / "pool", max_retries=0,
                      show_progress=False)
    assert sorted(r.task for r in pooled if r.error) == ["die", "die"]
    assert all(r.retryable and r.error.startswith("WorkerDied") for r in pooled if r.error)
    assert len(pooled) == 10 == len({r.key() for r in pooled})


def test_retry_errors_reruns_exactly_the_retryable_ones(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cfg = config("flaky_episode", ["a", "flaky1", "bad", "flaky2"], seeds=2)
    monkeypatch.setenv("FAKE_LLM_DOWN", "1")
    first = evaluate(cfg, tmp_path / "run", show_progress=False)
    assert sorted(r.task for r in first if r.retryable) == ["flaky1", "flaky1", "flaky2", "flaky2"]
    assert evaluate(cfg, tmp_path / "run", resume=True, show_progress=False) == first  # plain resume: nothing to run
    monkeypatch.delenv("FAKE_LLM_DOWN")
    with pytest.raises(UserError, match="pass --resume"):
        evaluate(cfg, tmp_path / "run", retry_errors=True, show_progress=False)
    after = evaluate(cfg, tmp_path / "run", resume=True, retry_errors=True, show_progress=False)
    assert not any(r.error for r in after) and len(after) == 8 == len(read_records(tmp_path / "run"))
    assert Counter(r.key() for r in read_records(tmp_path / "run")).most_common(1)[0][1] == 1
    assert len(read_records(tmp_path / "run" / "retried.jsonl")) == 4


def test_process_limiter_bounds_concurrent_llm_calls(tmp_path: Path) -> None:
    cfg = config("limited_episode", ["a", "b", "c", "d"], workers=3)
    records = evaluate(cfg, tmp_path / "lim", max_concurrent_llm=1, show_progress=False)
    assert [r.timings["holders"] for r in records] == [1.0] * 4
    unlimited = evaluate(cfg, tmp_path / "free", show_progress=False)
    assert max(r.timings["holders"] for r in unlimited) > 1


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def test_kill_9_then_resume_runs_every_episode_exactly_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    run = tmp_path / "run"
    cfg = config("slow_episode", [f"t{i}" for i in range(10)], seeds=2, workers=2)
    script = (
        "import sys; from pathlib import Path; from more_agent.eval.harness import evaluate; "
        "from more_agent.eval.store import RunConfig; "
        "evaluate(RunConfig.model_validate_json(sys.argv[1]), Path(sys.argv[2]), show_progress=False)"
    )
    env = {**os.environ, "PYTHONPATH": str(REPO), "FAKE_EPISODE_SECONDS": "0.2"}
    proc = subprocess.Popen(
        [sys.executable, "-c", script, cfg.model_dump_json(), str(run)], cwd=REPO, env=env, start_new_session=True
    )
    jsonl = run / "episodes.jsonl"
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and (not jsonl.exists() or jsonl.read_bytes().count(b"\n") < 4):
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
        before = read_records(jsonl)
        assert 4 <= len(before) < 20
        deadline = time.monotonic() + 10  # orphaned workers notice the dead parent and exit
        while _group_alive(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _group_alive(proc.pid)
    finally:
        if _group_alive(proc.pid):
            os.killpg(proc.pid, signal.SIGKILL)
    with open(jsonl, "ab") as fh:  # as if the kill had hit in the middle of a write
        fh.write(b'{"schema_version": 1, "task": "t9", "sce')
    monkeypatch.setenv("FAKE_EPISODE_SECONDS", "0")
    after = evaluate(cfg.model_copy(update={"workers": 1}), run, resume=True, show_progress=False)
    lines = jsonl.read_text().splitlines()
    assert len(lines) == 20 and all(json.loads(line)["task"] for line in lines)
    keys = Counter(r.key() for r in read_records(jsonl))
    assert len(keys) == 20 and set(keys.values()) == {1}
    assert outcome(after) == outcome([fake_episodes.deterministic_episode(s) for s in config_specs(cfg)])
    assert evaluate(cfg, run, resume=True, show_progress=False) == after  # nothing left to run


def test_missing_ray_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    from more_agent.eval.ray_backend import import_ray

    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(UserError, match=r"more-agent\[ray\]"):
        import_ray()


def test_trials_run_in_sequence_and_carry_their_failures(tmp_path: Path) -> None:
    """--trials 3 --long-term-memory: trial k of a world is given the summaries of its trials 0 .. k-1 (from
    their records), every record says its trial, and each trial has its own episode folder."""
    cfg = config("remembering_episode", ["a", "b"], seeds=2, workers=2).model_copy(
        update={"trials": 3, "long_term_memory": True}
    )
    records = evaluate(cfg, tmp_path / "run", show_progress=False)
    assert sorted(r.key() for r in records) == sorted(
        (t, "Rs_int", s, "oracle", k) for t in "ab" for s in (0, 1) for k in range(3)
    )
    for r in records:
        assert r.description == " | ".join(f"{r.task} s{r.seed} trial {k} failed" for k in range(r.trial))
    assert [r.trial for r in records] == sorted(r.trial for r in records)  # trial-major: rounds
    assert {s.trial for s in config_specs(cfg)} == {0, 1, 2}
    assert len({episode_dir(tmp_path / "run", r) for r in records}) == 12

    # Without memory no trial is told of another; one worker suffices to show it (the pool's rounds are shown above).
    no_memory = evaluate(
        cfg.model_copy(update={"long_term_memory": False, "workers": 1}), tmp_path / "plain", show_progress=False
    )
    assert all(r.description == "" for r in no_memory)


def test_a_trial_waits_for_the_retried_error_of_its_earlier_trial(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A retryable error in trial 0 holds trial 1 of that world back (its memory is not known yet); resume with
    --retry-errors runs both, and trial 1 then remembers the rerun trial 0."""
    cfg = config("remembering_episode", ["flaky", "ok"]).model_copy(update={"trials": 2, "long_term_memory": True})
    monkeypatch.setenv("FAKE_FLAKY", "1")
    first = evaluate(cfg, tmp_path / "run", show_progress=False)
    assert sorted((r.task, r.trial, r.retryable) for r in first) == [
        ("flaky", 0, True),
        ("ok", 0, False),
        ("ok", 1, False),
    ]
    monkeypatch.setenv("FAKE_FLAKY", "0")
    after = evaluate(cfg, tmp_path / "run", resume=True, retry_errors=True, show_progress=False)
    flaky = {r.trial: r for r in after if r.task == "flaky"}
    assert sorted(flaky) == [0, 1] and not flaky[0].error
    assert flaky[1].description == "flaky s0 trial 0 failed"
    assert len(read_records(tmp_path / "run")) == 4
