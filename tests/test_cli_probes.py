"""What a new user or a hostile input does to the CLI: one clear line, a documented exit status, no
traceback, and nothing already written lost (issue #13's probes)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.runlock import locked_run_dir

runner = CliRunner()
TASK = "putting_shopping_away"
TINY = Path(__file__).parent / "fixtures" / "tiny_scene.json"


@pytest.fixture(autouse=True)
def _no_llm(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("OPENAI_API_KEY", "OPENAI_BASE_URL", "MORE_AGENT_LLM", "MORE_AGENT_LLM_CONFIG", "MORE_AGENT_LLM_CACHE"):
        monkeypatch.delenv(name, raising=False)


def _invoke(args: list[str], **kw: object) -> tuple[int, str]:
    result = runner.invoke(app, args, **kw)  # type: ignore[arg-type]
    text = " ".join(result.output.split())
    assert "Traceback" not in result.output and not isinstance(result.exception, (AssertionError, OSError)), text
    return result.exit_code, text


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "[/]"], "unknown task '[/]'"),
        (["run", "[bold]x[/bold]"], "unknown task '[bold]x[/bold]'"),
        (["scene", "show", "Rs_int", "--seed", "-5"], "--seed"),
        (["run", TASK, "--seed", "-1"], "--seed"),
        (["tasks", "show", TASK, "--seed", "-3"], "--seed"),
        (["eval", "--tasks", ",".join(["store_beer"] * 30 + ["no_such_task"]), "--planner", "oracle", "--out", "{tmp}/z"],
         "unknown task 'no_such_task'"),
        (["eval", "--tasks", "store_beer", "--planner", "orcale", "--out", "{tmp}/z"], "closest: oracle"),
        (["eval", "--tasks", "store_beer", "--planner", "oracle", "--scene", "Rs_itn", "--out", "{tmp}/z"],
         "closest: Rs_int"),
        (["eval", "--tasks", "store_beer", "--planner", "more", "--out", "{tmp}/z"], "needs an LLM"),
        (["eval", "--tasks", "store_beer", "--planner", "more", "--llm", "openai:gpt-4o?api_key=sk-abcdefgh12345678",
          "--out", "{tmp}/z"], "must not contain credentials"),
        (["run", TASK, "--planner", "more", "--llm", "openai:gpt-4o?api_key=sk-abcdefgh12345678"],
         "must not contain credentials"),
        (["eval", "--tasks", "store_beer", "--planner", "oracle", "--out", "{tmp}/z", "--retry-errors"],
         "pass --resume too"),
    ],
)
def test_bad_names_and_values_exit_2_before_any_work(args: list[str], message: str, tmp_path: Path) -> None:
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    code, text = _invoke(args if "--out" in args or args[0] != "run" else [*args, "--out", str(tmp_path / "o")])
    assert code == 2, text
    assert message in text and "sk-abcdefgh" not in text
    assert not (tmp_path / "z").exists() and not (tmp_path / "o").exists()


def test_install_hint_keeps_its_brackets(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "llama_cpp", None)
    gguf = tmp_path / "m.gguf"
    gguf.write_bytes(b"GGUF")
    code, text = _invoke(["run", TASK, "--planner", "more", "--llm", f"llamacpp:{gguf}", "--out", str(tmp_path / "o")])
    assert code == 2 and "more-agent[llamacpp]" in text, text


@pytest.mark.parametrize("kind", ["file", "under_a_file"])
def test_out_that_cannot_be_written_is_refused_first(kind: str, tmp_path: Path) -> None:
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    out = afile if kind == "file" else afile / "sub"
    for args in (["run", TASK, "--out", str(out)],
                 ["eval", "--tasks", "store_beer", "--planner", "oracle", "--out", str(out)],
                 ["scene", "generate", "Rs_int", "--out", str(out / "s.json")]):
        code, text = _invoke(args)
        assert code == 2 and "afile" in text, text
    assert afile.read_text() == "keep me"


def test_episodes_jsonl_that_is_a_directory(tmp_path: Path) -> None:
    (tmp_path / "run" / "episodes.jsonl").mkdir(parents=True)
    code, text = _invoke(["eval", "--tasks", "store_beer", "--planner", "oracle", "--out", str(tmp_path / "run"),
                          "--resume"])
    assert code == 2 and "episodes.jsonl exists and is not a file" in text


def test_a_second_writer_exits_2_naming_the_holder(tmp_path: Path) -> None:
    run = tmp_path / "run"
    with locked_run_dir(run):
        code, text = _invoke(["eval", "--tasks", "store_beer", "--planner", "oracle", "--out", str(run), "--resume",
                              "--no-progress"])
    assert code == 2 and "is being written by pid" in text and "choose another --out" in text
    assert not (run / "episodes.jsonl").exists()


def test_cache_path_that_is_a_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MORE_AGENT_LLM_CACHE", str(tmp_path))
    monkeypatch.setenv("OPENAI_BASE_URL", "http://127.0.0.1:9/v1")
    code, text = _invoke(["run", TASK, "--planner", "more", "--llm", "openai:m", "--out", str(tmp_path / "o")])
    assert code == 2 and "is not a file" in text


def _scene(edit: Callable[[dict], None]) -> dict:
    scene = json.loads(TINY.read_text())
    edit(scene)
    return scene


def _nested(depth: int) -> str:
    return "[" * depth + "]" * depth


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (json.dumps(_scene(lambda s: s["rooms"][0]["bounds"].__setitem__(2, float("nan")))), "rooms[0].bounds[2]"),
        (json.dumps(_scene(lambda s: s["walls"][0].__setitem__("z_max", float("inf")))), "walls[0].z_max"),
        (json.dumps(_scene(lambda s: s["rooms"][1]["bounds"].__setitem__(2, 1e9))), "rooms[1].bounds[2]"),
        (json.dumps(_scene(lambda s: s["doors"][0].__setitem__("rooms", ["kitchen_0", "kitchen_0"]))), "doors[0]"),
        (json.dumps(_scene(lambda s: s.__setitem__("bounds", [-0.1, -0.1, 5000.0, 4.1]))), "bounds[2]"),
        (json.dumps(_scene(lambda s: s.__setitem__("bounds", [-900.0, -0.1, 900.0, 4.1]))), "over the limit of 200"),
        (_nested(100_000), "nested too deeply"),
    ],
)
def test_absurd_scene_files_are_rejected_with_the_field_path(text: str, message: str, tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    path.write_text(text)
    code, out = _invoke(["scene", "show", str(path)])
    assert code == 2 and message in out, out


def test_scene_render_says_which_file_it_wrote(tmp_path: Path) -> None:
    code, text = _invoke(["scene", "render", str(TINY), "--out", str(tmp_path / "plan")])
    assert code == 0 and f"wrote {tmp_path / 'plan.png'}" in text
    assert (tmp_path / "plan.png").stat().st_size > 1000


@pytest.mark.parametrize("episode_fn", ["slow_episode", "swallowing_episode"])
def test_ctrl_c_always_exits_130_and_records_nothing_after_it(episode_fn: str, tmp_path: Path) -> None:
    import os
    import signal
    import subprocess
    import sys
    import time

    from more_agent.eval.store import read_records

    repo = Path(__file__).parents[1]
    out = tmp_path / "run"
    cmd = [sys.executable, "-c", "from more_agent.cli import app; app(prog_name='more-agent')", "eval", "--tasks",
           ",".join(f"t{i}" for i in range(40)), "--planner", "oracle", "--out", str(out), "--no-progress",
           "--episode-fn", f"tests.eval.fake_episodes:{episode_fn}"]
    env = {**os.environ, "PYTHONPATH": str(repo), "FAKE_EPISODE_SECONDS": "0.3"}
    proc = subprocess.Popen(cmd, cwd=repo, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(read_records(out)) < 2:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err
    records = read_records(out)
    assert 2 <= len(records) < 40 and not any(r.error for r in records)
