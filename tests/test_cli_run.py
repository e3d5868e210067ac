"""``more-agent run``: the default output folder (bad input and summary lines: tests/test_cli.py)."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from more_agent.cli import app

runner = CliRunner()


def test_default_out_dir_names_task_scene_seed_planner(tmp_path, monkeypatch, pictures_on):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    result = runner.invoke(app, ["run", "putting_shopping_away", "--scene", "Rs_int", "--seed", "2", "--planner", "oracle"])
    assert result.exit_code == 0, result.output
    out = tmp_path / "runs" / "putting_shopping_away-Rs_int-2-oracle"
    record = json.loads((out / "episode.json").read_text())
    assert record["seed"] == 2 and record["planner"] == "oracle" and (out / "map.png").exists()
