"""Comparison plots: one PNG each, failure reasons read from the record."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from more_agent.eval.pictures import ENV_PICTURES
from more_agent.eval.report import REPORT_HTML, SUMMARY_CSV, SUMMARY_MD, SourcedRecord
from more_agent.eval.report_plots import PLOT_FILES, failure_reason, write_plots
from more_agent.eval.report_writer import write_reports
from more_agent.records import EpisodeRecord, Failure, LLMUsage


def rec(task: str, planner: str, **kw: object) -> EpisodeRecord:
    return EpisodeRecord(task=task, scene="Rs_int", seed=0, planner=planner, llm=None if planner == "oracle" else "openai:m", **kw)


def test_failure_reason_prefers_the_classified_cause_then_the_error() -> None:
    assert failure_reason(rec("t", "more", success=True)) is None
    assert failure_reason(rec("t", "more", failure=Failure(cause="never_observed"), error="x: y")) == "never_observed"
    assert failure_reason(rec("t", "more", termination="step_limit")) == "step_limit"
    assert failure_reason(rec("t", "more", error="LLM error (LLMTimeout): read timed out", error_kind="llm")) == "llm error"
    assert failure_reason(rec("t", "more")) == "unclassified"


def test_write_plots_draws_every_plot_even_with_missing_cells(tmp_path: Path) -> None:
    records = [
        rec("t1", "oracle", success=True, all_goals_met=True, task_progress=1.0, high_level_steps=7),
        rec("t2", "oracle", gave_up="oracle gave up: grasp failed 2 times", termination="done", high_level_steps=3),
        rec("t1", "more", failure=Failure(cause="step_limit"), high_level_steps=50,
            llm_usage=LLMUsage(calls=3, prompt_tokens=900, completion_tokens=60)),
    ]  # 'more' never ran t2: a blank cell in the heat map
    paths = write_plots(records, tmp_path)
    assert [p.name for p in paths] == list(PLOT_FILES.values())
    for p in paths:
        with Image.open(p) as im:
            assert im.format == "PNG" and im.width > 300 and im.height > 150
    assert write_plots([], tmp_path / "none") == []


def test_reports_without_pictures_leave_the_plots_out(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ENV_PICTURES, "off")
    records = [rec("t1", "oracle", success=True, all_goals_met=True, task_progress=1.0, high_level_steps=7)]
    paths = write_reports([SourcedRecord(r, tmp_path) for r in records], tmp_path / "report")
    assert [p.name for p in paths] == [SUMMARY_MD, SUMMARY_CSV, REPORT_HTML] and all(p.is_file() for p in paths)
    assert "## Plots" not in paths[0].read_text() and "plot_" not in paths[2].read_text()
    assert not list((tmp_path / "report").glob("*.png"))
