"""``more-agent eval --trials``: records per trial, the trials and LLM tables in the report, bad values."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.store import read_records
from tests.fakes.openai_server import FakeOpenAIServer
from tests.test_cli_faults import EVAL, server  # noqa: F401 - the fake server fixture

runner = CliRunner()


def test_eval_trials_records_each_trial_and_reports_them(server: FakeOpenAIServer, tmp_path: Path) -> None:  # noqa: F811
    out = tmp_path / "run"
    result = runner.invoke(app, [*EVAL, "--out", str(out), "--trials", "2"])
    assert result.exit_code == 0, result.output
    assert sorted(r.trial for r in read_records(out)) == [0, 1]
    flat = " ".join(result.output.split())
    assert "| System | trial | n | SR [%] | TP [%] |" in flat and "| any | 1 |" in flat
    assert "invalid answers [% of steps]" in flat and "0.0 (0/2)" in flat  # one done() step per trial
    summary = (out / "summary.md").read_text()
    assert "## Trials" in summary and "## LLM traffic" in summary
    again = runner.invoke(app, [*EVAL, "--out", str(out), "--trials", "3", "--resume"])
    assert again.exit_code == 2 and "trials: 2 -> 3" in " ".join(again.output.split())


def test_eval_refuses_fewer_than_one_trial(server: FakeOpenAIServer, tmp_path: Path) -> None:  # noqa: F811
    for bad in ("0", "-1"):
        result = runner.invoke(app, [*EVAL, "--out", str(tmp_path / "run"), "--trials", bad])
        assert result.exit_code == 2
        assert "Invalid value for '--trials': Input should be greater than or equal to 1" in " ".join(
            result.output.split()
        )
    assert not (tmp_path / "run").exists() and not server.requests
