"""The ``more-agent run`` command end to end: the default job, its files, and every bad-input exit."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.commands.run import NO_LLM_MESSAGE
from more_agent.robot_spec import full_turn_angles

runner = CliRunner()
TASK = "putting_shopping_away"
NO_LLM_ENV = {"OPENAI_API_KEY": "", "OPENAI_BASE_URL": "", "MORE_AGENT_LLM": "", "MORE_AGENT_LLM_CONFIG": ""}


@pytest.fixture(autouse=True)
def _no_llm(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in NO_LLM_ENV:
        monkeypatch.delenv(name, raising=False)


def test_default_run_without_llm_says_so_first_and_solves_with_grounded(tmp_path: Path, pictures_on: None) -> None:
    result = runner.invoke(app, ["run", TASK, "--scene", "Rs_int", "--out", str(tmp_path), "--save-frames"])
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[0] == NO_LLM_MESSAGE
    record = json.loads((tmp_path / "episode.json").read_text())
    assert record["planner"] == "grounded" and record["llm"] is None and record["success"] is True
    assert record["scene"] == "Rs_int" and record["error"] is None
    assert all(c["satisfied"] for c in record["goal_conditions"]) and len(record["goal_conditions"]) == 5
    assert {"task", "seed", "high_level_steps", "low_level_steps", "actions", "llm_usage", "timings"} <= set(record)
    assert (tmp_path / "map.png").stat().st_size > 10_000
    frames = sorted((tmp_path / "frames").glob("frame_*_rgb.png"))
    assert len(frames) > len(full_turn_angles()) + record["high_level_steps"]  # the initial turn, then the subpolicies' frames


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "putting_shoping_away"], "closest: putting_shopping_away"),
        (["run", TASK, "--scene", "Rs_itn"], "closest: Rs_int"),
        (["run", TASK, "--planner", "mroe"], "closest: more"),
        (["run", TASK, "--scene", "office_large"], "scene 'office_large' does not suit task 'putting_shopping_away'"),
        (["run", TASK, "--start", "kitchen"], "unknown start 'kitchen'; use --start with one of: random, random-area, task-room"),
        (["run", TASK, "--planner", "more"], "needs an LLM"),
        (["run", TASK, "--planner", "more", "--llm", "gpt-4o"], "openai:"),
    ],
)
def test_bad_input_exits_2_with_one_clear_line(args: list[str], message: str, tmp_path: Path) -> None:
    result = runner.invoke(app, [*args, "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output


def test_malformed_scene_file_names_the_bad_field(tmp_path: Path) -> None:
    scene = json.loads(Path("tests/fixtures/tiny_scene.json").read_text())
    scene["rooms"][0]["bounds"][2] = "wide"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(scene))
    result = runner.invoke(app, ["run", TASK, "--scene", str(bad), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "rooms[0].bounds[2]" in result.output and "Traceback" not in result.output
