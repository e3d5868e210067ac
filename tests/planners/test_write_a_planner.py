"""The planner of docs/write_a_planner.md runs as written: its code block, in an episode."""

from __future__ import annotations

import re
from pathlib import Path

from more_agent.eval.episode import run_episode
from more_agent.planners.base import make_planner
from more_agent.records import EpisodeSpec

DOC = Path(__file__).parents[2] / "docs" / "write_a_planner.md"
KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"


def _planner_code() -> str:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)[0]


def test_the_documented_planner_is_about_forty_lines() -> None:
    body = [line for line in _planner_code().splitlines() if line.strip()]
    assert 30 <= len(body) <= 50


def test_the_documented_planner_runs_an_episode_to_done() -> None:
    exec(compile(_planner_code(), str(DOC), "exec"), {})  # registers 'explorer'
    planner = make_planner("explorer")
    record = run_episode(EpisodeSpec(task="putting_shopping_away", scene=str(KITCHEN), seed=0, planner="explorer"),
                         planner=planner)
    assert record.error is None and record.termination == "done" and record.done_called
    assert 1 <= record.high_level_steps <= planner.max_explores + 1
    assert [a.name for a in record.actions][:-1] == ["explore"] * (record.high_level_steps - 1)
    assert record.observed_objects and record.failure is not None  # it saw task objects, moved none
