"""The exit-status contract (docs/evaluation.md, "Exit status"), one status at a time, and the hostile
inputs of issue 23 through the real CLI: one line and the documented status, never a traceback,
nothing already written lost, no escape sequence on the terminal."""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.pictures import ENV_PICTURES
from more_agent.eval.runlock import locked_run_dir
from more_agent.eval.store import read_records
from tests.fakes.openai_server import FakeOpenAIServer, Status
from tests.test_cli_faults import KEY, RUN, TASK, server  # noqa: F401 - the fixture

runner = CliRunner()
REPO = Path(__file__).parents[1]
FAKE = "tests.eval.fake_episodes"
KITCHEN = REPO / "tests" / "fixtures" / "tasks_kitchen_scene.json"
ORACLE = ["run", TASK, "--scene", str(KITCHEN), "--planner", "oracle"]
ESC = "\x1b[31mred\x1b]0;title\x07"


def _eval(out: Path, fn: str = "deterministic_episode", tasks: str = TASK, *extra: str) -> list[str]:
    return ["eval", "--tasks", tasks, "--planner", "oracle", "--out", str(out), "--no-progress",
            "--episode-fn", f"{FAKE}:{fn}", *extra]


def _invoke(args: list[str]) -> tuple[int, str]:
    result = runner.invoke(app, args)
    assert "Traceback" not in result.output and not isinstance(result.exception, (AssertionError, OSError)), result.output
    assert "\x1b" not in result.output
    return result.exit_code, " ".join(result.output.split())


@pytest.fixture(autouse=True)
def _no_llm_settings(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("MORE_AGENT_LLM", "MORE_AGENT_ROOM_MODEL"):
        monkeypatch.delenv(name, raising=False)


# -- the contract, one status at a time --------------------------------------------------------


def test_0_every_episode_ran_whatever_it_scored(tmp_path: Path) -> None:
    code, text = _invoke(_eval(tmp_path / "run", "deterministic_episode", TASK, "--seeds", "3"))
    assert code == 0 and len(read_records(tmp_path / "run")) == 3, text


def test_1_an_episode_raised(tmp_path: Path) -> None:
    code, text = _invoke(_eval(tmp_path / "run", "raising_episode", "good,bad_one"))
    assert code == 1 and "system error" in text, text
    assert len(read_records(tmp_path / "run")) == 2


def test_1_every_request_refused_with_401(server: FakeOpenAIServer, tmp_path: Path) -> None:  # noqa: F811
    server.push(*[Status(401, "bad key")] * 5)
    args = ["eval", "--tasks", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", "openai:fake-model",
            "--out", str(tmp_path / "run"), "--no-progress"]
    code, text = _invoke(args)
    assert code == 1, text
    (record,) = read_records(tmp_path / "run")
    assert "LLMAuthError" in (record.error or "") and not record.retryable


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--seeds", "3000000"], "--seeds"),
        (["--seeds", str(10**20)], "--seeds"),
        (["--ray-address", "garbage"], "--ray-address 'garbage'"),
    ],
)
def test_2_bad_numbers_and_addresses(args: list[str], message: str, tmp_path: Path) -> None:
    code, text = _invoke(_eval(tmp_path / "run", "deterministic_episode", TASK, *args))
    assert code == 2 and message in text, text
    assert not (tmp_path / "run" / "run.json").exists()


def test_2_a_seed_of_240_digits(tmp_path: Path) -> None:
    code, text = _invoke([*ORACLE, "--seed", "7" * 240, "--out", str(tmp_path / "ep")])
    assert code == 2 and "--seed" in text and not (tmp_path / "ep").exists(), text


def test_75_a_locked_cache_is_transient_and_retry_errors_reruns_it(server: FakeOpenAIServer, tmp_path: Path) -> None:  # noqa: F811
    import sqlite3

    with (tmp_path / "llm.toml").open("a") as f:  # the server fixture's config
        f.write("cache_busy_timeout_s = 0.2\n")
    holder = sqlite3.connect(tmp_path / "cache.sqlite", isolation_level=None)
    holder.execute("CREATE TABLE filler (x)")
    holder.execute("BEGIN EXCLUSIVE")
    args = ["eval", "--tasks", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", "openai:fake-model",
            "--out", str(tmp_path / "run"), "--no-progress"]
    code, text = _invoke(args)
    holder.close()
    assert code == 75, text
    (record,) = read_records(tmp_path / "run")
    assert record.retryable and "CacheLocked" in (record.error or "")
    code, text = _invoke([*args, "--resume", "--retry-errors"])
    assert code == 0, text


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_130_and_143_for_signals_without_worker_tracebacks(sig: int, status: int, tmp_path: Path) -> None:
    out = tmp_path / "run"
    cmd = [sys.executable, "-c", "from more_agent.cli import app; app(prog_name='more-agent')",
           *_eval(out, "slow_episode", ",".join(f"t{i}" for i in range(40))), "--workers", "2"]
    env = {**os.environ, "PYTHONPATH": str(REPO), "FAKE_EPISODE_SECONDS": "0.3"}
    proc = subprocess.Popen(cmd, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(read_records(out)) < 2:
        time.sleep(0.05)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert "Traceback" not in err and "Exception ignored" not in err and "interrupted" in err, err


# -- folders that lie ----------------------------------------------------------------------------


def test_run_takes_the_folder_lock(tmp_path: Path) -> None:
    with locked_run_dir(tmp_path / "ep"):
        code, text = _invoke([*ORACLE, "--out", str(tmp_path / "ep")])
    assert code == 2 and "is being written by" in text, text
    assert not (tmp_path / "ep" / "timeline.jsonl").exists()


def test_run_refuses_a_folder_of_another_episode_and_cleans_its_own(tmp_path: Path) -> None:
    ep = tmp_path / "ep"
    code, _ = _invoke([*ORACLE, "--seed", "1", "--out", str(ep)])
    assert code == 0
    before = (ep / "episode.json").read_bytes()
    code, text = _invoke([*ORACLE, "--seed", "2", "--out", str(ep)])
    assert code == 2 and "holds another episode" in text, text
    assert (ep / "episode.json").read_bytes() == before
    (ep / "steps.jsonl").write_text('{"step": 0, "exchanges": [{"messages": "STALE"}]}\n')  # an earlier LLM run's log
    code, text = _invoke([*ORACLE, "--seed", "1", "--out", str(ep)])
    assert code == 0 and not (ep / "steps.jsonl").exists(), text


def test_no_file_is_written_through_a_symlink(tmp_path: Path, pictures_on: None, monkeypatch: pytest.MonkeyPatch) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    ep = tmp_path / "ep"
    ep.mkdir()
    (ep / "episode.json").symlink_to(victim)
    (ep / "map.png").symlink_to(victim)
    code, text = _invoke([*ORACLE, "--out", str(ep)])
    assert code == 0 and victim.read_text() == "precious", text
    (ep / ".lock").unlink()
    (ep / ".lock").symlink_to(victim)
    code, text = _invoke([*ORACLE, "--out", str(ep)])
    assert code == 2 and "symlink" in text and victim.read_text() == "precious", text
    monkeypatch.setenv(ENV_PICTURES, "0")  # map.png above needed the pictures; summary.md below does not
    run = tmp_path / "run"
    assert _invoke(_eval(run))[0] == 0
    (run / "summary.md").unlink()
    (run / "summary.md").symlink_to(victim)
    code, text = _invoke(["report", str(run), "--out", str(run)])
    assert code == 0 and victim.read_text() == "precious", text


def test_resume_with_another_llm_runs_its_episodes_and_run_json_says_both(tmp_path: Path) -> None:
    run = tmp_path / "run"
    args = ["eval", "--tasks", TASK, "--planner", "more", "--out", str(run), "--no-progress",
            "--episode-fn", f"{FAKE}:deterministic_episode"]
    assert _invoke([*args, "--llm", "openai:a"])[0] == 0
    code, text = _invoke([*args, "--llm", "openai:b", "--resume", "--allow-mixed"])
    assert code == 0, text
    assert sorted(str(r.llm) for r in read_records(run)) == ["openai:a", "openai:b"]
    config = json.loads((run / "run.json").read_text())
    assert config["llm"] == "openai:b" and [e["llm"] for e in config["earlier"]] == ["openai:a"]


@pytest.mark.parametrize("name", ["episode.json", "steps.jsonl", "timeline.jsonl"])
def test_view_of_a_torn_file_is_one_line(name: str, tmp_path: Path) -> None:
    ep = tmp_path / "ep"
    assert _invoke([*ORACLE, "--out", str(ep)])[0] == 0
    (ep / "steps.jsonl").write_text('{"step": 0, "exchanges": []}\n')
    (ep / name).write_text((ep / name).read_text()[:20])
    code, text = _invoke(["view", str(ep)])
    assert code == 2 and name in text, text


@pytest.mark.parametrize("kind", ["too_long", "dangling", "looping", "readonly"])
def test_paths_that_cannot_be_used_are_one_line(kind: str, tmp_path: Path) -> None:
    out = {"too_long": tmp_path / ("x" * 300), "dangling": tmp_path / "dangling", "looping": tmp_path / "loop",
           "readonly": Path("/sys/more-agent-test/out")}[kind]
    if kind == "dangling":
        out.symlink_to(tmp_path / "nowhere" / "at_all")
    if kind == "looping":
        out.symlink_to(out)
    code, text = _invoke([*ORACLE, "--out", str(out)])
    assert code == 2, text
    run = tmp_path / "run"
    assert _invoke(_eval(run))[0] == 0
    code, text = _invoke(["report", str(run), "--out", str(out)])
    assert code == 2, text


def test_a_disk_that_fills_up_during_run_viewer_leaves_no_empty_record(tmp_path: Path,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    from more_agent import safe_files

    real_write, budget = os.write, [150_000]

    def filling(fd: int, data: bytes) -> int:
        budget[0] -= len(data)
        if budget[0] < 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(fd, data)

    monkeypatch.setattr(safe_files.os, "write", filling)
    ep = tmp_path / "ep"
    code, text = _invoke([*ORACLE, "--out", str(ep), "--viewer"])
    assert code == 75 and "No space left" in text, text
    assert not (ep / "episode.json").exists() or (ep / "episode.json").stat().st_size > 0


@pytest.mark.parametrize("kind", ["nested", "bom"])
def test_task_files_deeply_nested_or_with_a_bom(kind: str, tmp_path: Path) -> None:
    tasks = tmp_path / "tasks.json"
    tasks.write_bytes(b"[" * 100_000 + b"]" * 100_000 if kind == "nested" else b"\xef\xbb\xbf" + TASK.encode() + b"\n")
    code, text = _invoke(_eval(tmp_path / "run", "deterministic_episode", str(tasks)))
    if kind == "nested":
        assert code == 2 and "tasks.json" in text, text
    else:
        assert code == 0 and [r.task for r in read_records(tmp_path / "run")] == [TASK], text


def test_escape_sequences_never_reach_the_terminal(server: FakeOpenAIServer, tmp_path: Path) -> None:  # noqa: F811
    scene = json.loads(KITCHEN.read_text())
    (tmp_path / "scene.json").write_text(json.dumps({**scene, "name": f"kitchen_{ESC}"}))
    code, text = _invoke(["run", TASK, "--scene", str(tmp_path / "scene.json"), "--planner", "oracle",
                          "--out", str(tmp_path / "a")])  # _invoke asserts no escape reached the output
    assert code == 0 and "kitchen_red" in text, text
    server.push(*[Status(400, f"bad {ESC} request")] * 3)
    code, text = _invoke([*RUN, "--out", str(tmp_path / "b")])
    assert code == 1, text


def test_summary_md_escapes_html_from_a_model_name(tmp_path: Path) -> None:
    run = tmp_path / "run"
    code, text = _invoke([*_eval(run), "--llm", "openai:<img src=x onerror=alert(1)>"])
    assert code == 0, text
    summary = (run / "summary.md").read_text()
    assert "<img" not in summary and "&lt;img src=x onerror=alert(1)&gt;" in summary


def test_a_key_in_the_room_model_is_refused_and_written_nowhere(server: FakeOpenAIServer, tmp_path: Path,  # noqa: F811
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MORE_AGENT_ROOM_MODEL", f"roomy?api_key={KEY}")
    code, text = _invoke([*RUN, "--out", str(tmp_path / "ep")])
    assert code == 2 and "room_model" in text and KEY not in text, text
    assert not any(KEY.encode() in p.read_bytes() for p in tmp_path.rglob("*") if p.is_file())
