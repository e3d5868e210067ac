"""``--perception`` on ``run`` and ``eval``: bad values fail first with the valid keys; a run keeps its mode."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from more_agent.cli import app

runner = CliRunner()
FAKE = ["--episode-fn", "tests.eval.fake_episodes:deterministic_episode", "--no-progress"]


def test_a_bad_perception_value_is_one_error_naming_the_keys(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(
        app, ["run", "putting_shopping_away", "--planner", "oracle", "--out", str(out), "--perception", "noisy:blur=1"]
    )
    assert result.exit_code == 2 and "valid keys: confusion, miss, fragment, merge, depth, drift, room" in result.output
    assert not out.exists()
    result = runner.invoke(
        app, ["eval", "--tasks", "a", "--planner", "oracle", "--out", str(out), "--perception", "noisy:miss=3", *FAKE]
    )
    assert result.exit_code == 2 and "miss" in result.output and not out.exists()


def test_a_resumed_run_must_keep_its_perception(tmp_path: Path) -> None:
    out = tmp_path / "run"
    first = ["eval", "--tasks", "a,b", "--planner", "oracle", "--out", str(out), *FAKE]
    result = runner.invoke(app, [*first, "--perception", "noisy:depth=0.05"])
    assert result.exit_code == 0, result.output
    assert json.loads((out / "run.json").read_text())["perception"] == "noisy:depth=0.05"
    result = runner.invoke(app, [*first, "--resume", "--perception", "gt"])
    assert result.exit_code == 2 and "perception: 'noisy:depth=0.05' -> 'gt'" in result.output
