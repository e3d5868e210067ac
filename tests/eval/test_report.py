"""Reports: Table I markdown, CSV, HTML escaping and thumbnails, merging runs, the CLI commands."""

from __future__ import annotations

import base64
import csv
import io
from pathlib import Path

from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.report import SourcedRecord, load_runs, summary_csv, summary_markdown
from more_agent.eval.report_html import render_report
from more_agent.eval.report_writer import write_reports
from more_agent.eval.store import EpisodeWriter, episode_dirname
from more_agent.records import ActionRecord, EpisodeRecord, GoalCondition

PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="
)
EVIL = "<script>alert(1)</script>"


def rec(task: str, planner: str = "more", **kw: object) -> EpisodeRecord:
    return EpisodeRecord(
        task=task,
        scene="Rs_int",
        seed=0,
        planner=planner,
        llm="openai:gpt-4o" if planner != "oracle" else None,
        goal_conditions=[GoalCondition(text="(open fridge_1)", satisfied=True, objects=["fridge_1"])],
        observed_objects=["fridge_1"],
        task_progress=1.0,
        all_goals_met=True,
        trajectory=[(0.0, 0.0), (1.5, 2.0)],
        **kw,
    )


def make_run(d: Path, records: list[EpisodeRecord]) -> Path:
    d.mkdir(parents=True)
    with EpisodeWriter(d / "episodes.jsonl") as w:
        for r in records:
            w.append(r)
    return d


def test_markdown_and_csv_have_a_row_per_system_and_task() -> None:
    records = [rec("t1", success=True), rec("t2"), rec("t1", "oracle", success=True)]
    md = summary_markdown(records)
    assert "| more (openai:gpt-4o) | 2 | 2 | 0 | 50.0 [" in md and "| oracle | 1 | 1 | 0 | 100.0 [" in md
    rows = list(csv.DictReader(io.StringIO(summary_csv(records))))
    assert [(r["system"], r["task"]) for r in rows] == [
        ("more (openai:gpt-4o)", "ALL"),
        ("oracle", "ALL"),
        ("more (openai:gpt-4o)", "t1"),
        ("more (openai:gpt-4o)", "t2"),
        ("oracle", "t1"),
    ]
    assert float(rows[0]["SR"]) == 0.5 and float(rows[0]["SR_low"]) < 0.5 < float(rows[0]["SR_high"])
    # beside Table I: what differs from the paper's setting (rendering, ground-truth captions, magic reach)
    caveats = md.split("## Failure causes")[0]
    assert "flat-shaded boxes" in caveats and "ground-truth" in caveats and "magic actions" in caveats


def test_csv_has_an_overall_row_per_trial_when_a_run_has_trials() -> None:
    records = [rec("t1", trial=0), rec("t1", trial=1, success=True), rec("t2", trial=1, success=True)]
    rows = [(r["task"], r["trial"], r["n"], r["SR"]) for r in csv.DictReader(io.StringIO(summary_csv(records)))]
    assert rows == [
        ("ALL", "ALL", "3", "0.666667"),
        ("ALL", "0", "1", "0.000000"),
        ("ALL", "1", "2", "1.000000"),
        ("t1", "ALL", "2", "0.500000"),
        ("t2", "ALL", "1", "1.000000"),
    ]
    single = list(csv.DictReader(io.StringIO(summary_csv([rec("t1")]))))
    assert [r["trial"] for r in single] == ["ALL", "ALL"]


def test_rtp_cells_say_n_when_episodes_have_none(tmp_path: Path) -> None:
    blind = rec("t2").model_copy(update={"observed_objects": []})  # saw no task object: no rTP
    records = [rec("t1"), blind]
    md = summary_markdown(records)
    assert "| more (openai:gpt-4o) | 2 | 2 | 0 | 0.0 [" in md and "100.0 [100.0, 100.0] (n=1) |" in md
    assert "| more (openai:gpt-4o) | t2 | 1 | 0 | 0.0 [0.0, 79.3] | 100.0 [20.7, 100.0] | 100.0 [100.0, 100.0] | n/a |" in md
    rows = {r["task"]: r for r in csv.DictReader(io.StringIO(summary_csv(records)))}
    assert (rows["ALL"]["rTP"], rows["ALL"]["n_rTP"], rows["t2"]["rTP"], rows["t2"]["n_rTP"]) == ("1.000000", "1", "", "0")
    html = render_report([SourcedRecord(blind, tmp_path)])
    assert "rTP n/a" in html and "<td>n/a</td>" in html
    assert '<p class="caveats">' in html and "flat-shaded boxes" in html.split("<h2>Episodes</h2>")[0]


def test_html_escapes_all_record_text(tmp_path: Path) -> None:
    evil = rec(
        f"task{EVIL}",
        description=EVIL,
        actions=[ActionRecord(step=0, name=EVIL, arguments=[EVIL], ok=False, feedback=f"failed: {EVIL}")],
        error=EVIL,
        traceback=EVIL,
    )
    html = render_report([SourcedRecord(evil, tmp_path)])
    assert "<script>" not in html
    assert html.count("&lt;script&gt;alert(1)&lt;/script&gt;") >= 6


def test_thumbnail_links_map_png_else_draws_trajectory_and_links_the_viewer(tmp_path: Path) -> None:
    with_map, without = rec("t1"), rec("t2")
    ep_dir = tmp_path / "run" / "episodes" / episode_dirname("t1", None, 0, "more")
    ep_dir.mkdir(parents=True)
    (ep_dir / "map.png").write_bytes(PNG)
    (ep_dir / "viewer.html").write_text("<!DOCTYPE html>")
    sourced = [SourcedRecord(with_map, tmp_path / "run"), SourcedRecord(without, tmp_path / "run")]
    html = render_report(sourced, out_dir=tmp_path / "cmp")
    assert "base64" not in html  # pictures are files the page links to, not inlined
    assert html.count('src="../run/episodes/t1__auto__s0__more/map.png"') == 1
    assert html.count('href="../run/episodes/t1__auto__s0__more/viewer.html"') == 1
    assert html.count("<polyline") == 1


def test_load_runs_merges_and_drops_duplicates(tmp_path: Path) -> None:
    a = make_run(tmp_path / "a", [rec("t1"), rec("t2")])
    b = make_run(tmp_path / "b", [rec("t1", success=True), rec("t1", "oracle")])
    sourced, dropped = load_runs([a, b])
    assert dropped == 1
    assert [(s.record.planner, s.record.task, s.run_dir.name) for s in sourced] == [
        ("more", "t1", "a"),
        ("more", "t2", "a"),
        ("oracle", "t1", "b"),
    ]
    paths = write_reports(sourced, tmp_path / "out")
    assert all(p.stat().st_size > 0 for p in paths)


def test_cli_eval_then_report(tmp_path: Path) -> None:
    runner = CliRunner()
    args = ["eval", "--tasks", "a,bad", "--planner", "oracle", "--seeds", "2", "--no-progress"]
    args += ["--episode-fn", "tests.eval.fake_episodes:raising_episode", "--out", str(tmp_path / "run")]
    result = runner.invoke(app, args)
    assert result.exit_code == 1, result.output  # episodes that raised: a system error (exit-status contract)
    assert "| oracle | 4 | 2 | 2 |" in result.output
    assert {p.name for p in (tmp_path / "run").iterdir()} >= {"episodes.jsonl", "run.json", "summary.md", "summary.csv", "report.html"}
    again = runner.invoke(app, args)
    assert again.exit_code == 2 and "--resume" in again.output
    report = runner.invoke(app, ["report", str(tmp_path / "run"), "--per-task", "--out", str(tmp_path / "cmp")])
    assert report.exit_code == 0 and "| oracle | bad | 2 | 2 |" in report.output
    assert (tmp_path / "cmp" / "report.html").is_file()
    missing = runner.invoke(app, ["report", str(tmp_path / "nothing")])
    assert missing.exit_code == 2


def test_cli_eval_refuses_unknown_task_names_for_the_real_episode(tmp_path: Path) -> None:
    args = ["eval", "--tasks", "putting_away_halloween_decoratoins", "--planner", "oracle", "--out", str(tmp_path / "r")]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2 and "putting_away_Halloween_decorations" in result.output
    assert not (tmp_path / "r").exists()
