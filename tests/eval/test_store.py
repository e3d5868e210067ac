"""episodes.jsonl durability (torn lines), run directories, resume bookkeeping."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from more_agent.errors import UserError
from more_agent.eval.runlock import RunFolderBusy, locked_run_dir
from more_agent.eval.store import (
    EpisodeWriter,
    RunConfig,
    TornStoreError,
    episode_dirname,
    pending,
    prepare_run_dir,
    read_records,
    read_run_config,
    retire_retryable,
)
from more_agent.records import EpisodeRecord, EpisodeSpec


def rec(task: str, seed: int = 0, scene: str = "Rs_int") -> EpisodeRecord:
    return EpisodeRecord(task=task, scene=scene, seed=seed, planner="oracle")


def write(path: Path, records: list[EpisodeRecord]) -> None:
    with EpisodeWriter(path) as w:
        for r in records:
            w.append(r)


def config(**kw: object) -> RunConfig:
    return RunConfig(**{"planner": "oracle", "tasks": ["a"], "seeds": [0], "episode_fn": "m:f", **kw})


def test_roundtrip_one_line_per_record(tmp_path: Path) -> None:
    p = tmp_path / "episodes.jsonl"
    write(p, [rec("a"), rec("b", 1)])
    assert p.read_text().count("\n") == 2
    assert [r.key() for r in read_records(p)] == [("a", "Rs_int", 0, "oracle", 0), ("b", "Rs_int", 1, "oracle", 0)]
    assert read_records(tmp_path) == read_records(p)
    assert read_records(tmp_path / "missing.jsonl") == []


@pytest.mark.parametrize("tail", [b'{"task": "c", "sce', b'{"task":"x"}', rec("c").model_dump_json().encode()])
def test_torn_last_line_is_dropped_and_repaired(tmp_path: Path, tail: bytes) -> None:
    p = tmp_path / "episodes.jsonl"
    write(p, [rec("a"), rec("b")])
    good = p.read_bytes()
    p.write_bytes(good + tail)
    assert [r.task for r in read_records(p)] == ["a", "b"]
    assert p.read_bytes() == good + tail  # reading alone does not modify
    read_records(p, repair=True)
    assert p.read_bytes() == good
    write(p, [rec("c")])
    assert [r.task for r in read_records(p)] == ["a", "b", "c"]


def test_bad_line_in_the_middle_is_an_error(tmp_path: Path) -> None:
    p = tmp_path / "episodes.jsonl"
    p.write_bytes(rec("a").model_dump_json().encode() + b"\nnot json\n" + rec("b").model_dump_json().encode() + b"\n")
    with pytest.raises(TornStoreError, match="unreadable record"):
        read_records(p)


def test_prepare_refuses_non_empty_dir_without_resume(tmp_path: Path) -> None:
    (tmp_path / "something").write_text("x")
    with pytest.raises(UserError, match="not empty.*--resume"):
        prepare_run_dir(tmp_path, config(), resume=False)


def test_prepare_resume_checks_planner_and_returns_records(tmp_path: Path) -> None:
    assert prepare_run_dir(tmp_path / "run", config(), resume=False) == []
    write(tmp_path / "run" / "episodes.jsonl", [rec("a")])
    assert read_run_config(tmp_path / "run") == config()
    with pytest.raises(UserError, match="planner: 'oracle' -> 'more'; llm: None -> 'openai:gpt-4o'.*--allow-mixed"):
        prepare_run_dir(tmp_path / "run", config(planner="more", llm="openai:gpt-4o"), resume=True)
    with pytest.raises(UserError, match="tasks: a -> a,b"):
        prepare_run_dir(tmp_path / "run", config(tasks=["a", "b"]), resume=True)
    mixed = prepare_run_dir(tmp_path / "run", config(tasks=["a", "b"]), resume=True, allow_mixed=True)
    assert [r.task for r in mixed] == ["a"]
    assert read_run_config(tmp_path / "run").tasks == ["a", "b"]


def test_resume_without_run_json_checks_the_records(tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    write(run / "episodes.jsonl", [rec("a")])  # run.json lost
    with pytest.raises(UserError, match="planner: 'oracle' -> 'more'"):
        prepare_run_dir(run, config(planner="more"), resume=True)
    assert [r.task for r in prepare_run_dir(run, config(tasks=["a"]), resume=True)] == ["a"]


def test_resume_must_keep_the_history_and_older_runs_ran_the_longer_one(tmp_path: Path) -> None:
    llm = {"planner": "more", "llm": "openai:gpt-4o"}
    run = tmp_path / "run"
    prepare_run_dir(run, config(**llm, history="lasting"), resume=False)
    with pytest.raises(UserError, match="history: 'lasting' -> 'paper'"):
        prepare_run_dir(run, config(**llm), resume=True)
    old = tmp_path / "old"  # run.json of a version before the option: its LLM planner showed the longer history
    prepare_run_dir(old, config(**llm), resume=False)
    data = json.loads((old / "run.json").read_text())
    (old / "run.json").write_text(json.dumps({k: v for k, v in data.items() if k != "history"}))
    assert read_run_config(old).history == "lasting"
    with pytest.raises(UserError, match="history: 'lasting' -> 'paper'"):
        prepare_run_dir(old, config(**llm), resume=True)
    assert prepare_run_dir(old, config(**llm, history="lasting"), resume=True) == []
    oracle = tmp_path / "oracle"  # no LLM: the history never mattered, the default is assumed
    prepare_run_dir(oracle, config(), resume=False)
    (oracle / "run.json").write_text(json.dumps(config().model_dump(exclude={"history"})))
    assert prepare_run_dir(oracle, config(), resume=True) == []


def test_run_folder_lock_refuses_a_second_writer_and_dies_with_its_holder(tmp_path: Path) -> None:
    with locked_run_dir(tmp_path):
        with pytest.raises(RunFolderBusy, match=rf"being written by pid {os.getpid()} on "):
            with locked_run_dir(tmp_path):
                pass
    holder = subprocess.Popen([sys.executable, "-c", (
        "import sys, time; from pathlib import Path; from more_agent.eval.runlock import locked_run_dir\n"
        "with locked_run_dir(Path(sys.argv[1])):\n    print('locked', flush=True); time.sleep(60)"
    ), str(tmp_path)], stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "locked"
    with pytest.raises(RunFolderBusy, match=f"pid {holder.pid}"):
        with locked_run_dir(tmp_path):
            pass
    holder.kill()  # kill -9: the OS releases the lock
    holder.wait()
    with locked_run_dir(tmp_path):
        pass


def test_retire_retryable_moves_them_aside(tmp_path: Path) -> None:
    records = [rec("a"), rec("b").model_copy(update={"error": "LLM error", "error_kind": "llm", "retryable": True}), rec("c")]
    write(tmp_path / "episodes.jsonl", records)
    kept = retire_retryable(tmp_path, read_records(tmp_path))
    assert [r.task for r in kept] == ["a", "c"] == [r.task for r in read_records(tmp_path)]
    assert [r.task for r in read_records(tmp_path / "retried.jsonl")] == ["b"]


def test_pending_matches_unset_scene_to_any_scene() -> None:
    specs = [EpisodeSpec(task=t, seed=s) for t in ("a", "b") for s in (0, 1)]
    done = [rec("a", 0, "Rs_int"), rec("b", 1, "Beechwood_0_int")]
    assert [(s.task, s.seed) for s in pending(specs, done)] == [("a", 1), ("b", 0)]
    pinned = [EpisodeSpec(task="a", scene="Pomaria_1_int", seed=0)]
    assert pending(pinned, done) == pinned


def test_dirname() -> None:
    assert episode_dirname("a/b", None, 3, "more") == "a_b__auto__s3__more"


def test_pending_knows_a_scene_file_by_the_name_inside() -> None:
    tiny = str(Path(__file__).parents[1] / "fixtures" / "tiny_scene.json")
    spec = EpisodeSpec(task="a", scene=tiny, seed=0)
    assert pending([spec], [rec("a", 0, "tiny")]) == []
    assert pending([spec], [rec("a", 0, "Rs_int")]) == [spec]
