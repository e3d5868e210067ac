"""The episode record contract of an oracle episode: fields, files, strict bad input (runner rules: test_episode_runner)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from more_agent.errors import UserError
from more_agent.eval.episode import run_episode
from more_agent.eval.episode_folder import EpisodeFolder
from more_agent.eval.pictures import ENV_PICTURES
from more_agent.planners.base import DONE
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World

SPEC = EpisodeSpec(task="putting_shopping_away", scene="Rs_int", seed=0, planner="oracle")


def test_oracle_episode_record_fields_and_files(tmp_path, pictures_on):
    record = run_episode(SPEC, out_dir=tmp_path)
    assert record.success and record.all_goals_met and record.done_called and record.error is None
    assert record.task_progress == 1.0 and record.goal_conditions and all(c.satisfied for c in record.goal_conditions)
    assert record.actions[-1].name == DONE and record.high_level_steps == len(record.actions)
    assert all(a.ok for a in record.actions) and all(a.feedback for a in record.actions)
    assert record.low_level_steps == sum(a.low_level_steps for a in record.actions) > 0
    assert len(record.trajectory) > 2 and record.llm is None and record.llm_usage.calls == 0
    assert set(record.timings) >= {"instantiate", "plan", "act", "sense", "total"}
    saved = json.loads((tmp_path / "episode.json").read_text())
    assert saved["success"] is True and saved["task"] == SPEC.task and saved["scene"] == "Rs_int"
    assert (tmp_path / "map.png").read_bytes()[:4] == b"\x89PNG"


def test_strict_raises_bad_input_instead_of_recording_it():
    with pytest.raises(UserError, match="closest"):
        run_episode(SPEC.model_copy(update={"planner": "oracel"}), strict=True)
    record = run_episode(SPEC.model_copy(update={"scene": "Rs_itn"}))
    assert not record.success and "closest: Rs_int" in (record.error or "") and record.traceback is None


def test_the_folder_holds_each_steps_trace_and_frames(tmp_path):
    from more_agent.eval.episode_folder import EpisodeFolder

    record = run_episode(SPEC, out_dir=tmp_path, viewer=True)  # frames and graphs, without graph pictures
    folder = EpisodeFolder(tmp_path)
    steps = range(record.high_level_steps)
    assert all(folder.graph_path(s).is_file() and folder.graph_path(s, "_occupancy.png").is_file() for s in steps)
    assert not list(folder.graphs_dir.glob("step_???.png")) and not folder.steps_path.exists()  # the oracle keeps no log
    timeline = [json.loads(line) for line in folder.timeline_path.read_text().splitlines()]
    assert [t["step"] for t in timeline] == list(steps)
    assert timeline[-1]["low_level_steps"] == record.low_level_steps and timeline[-1]["path_len"] == len(record.trajectory)
    frames = timeline[-1]["frames"]
    assert frames == len(list(folder.frames_dir.glob("frame_*_rgb.png"))) > record.high_level_steps
    assert folder.frame_path(frames - 1, "semantic").is_file() and not folder.frame_path(frames, "rgb").exists()


def test_without_pictures_the_folder_draws_no_map(tmp_path, monkeypatch):
    scene = load_scene(Path(__file__).parents[1] / "fixtures" / "tiny_scene.json")
    world, labels = World.from_scene(scene), InstanceLabels()
    record = EpisodeRecord(task="t", scene=scene.name, seed=0, planner="oracle", trajectory=[(1.0, 1.0), (2.0, 1.5)])
    folder = EpisodeFolder(tmp_path)
    monkeypatch.setenv(ENV_PICTURES, "0")
    folder.write_map(record, world, labels, set())
    assert not folder.map_path.exists()
    monkeypatch.setenv(ENV_PICTURES, "1")
    folder.write_map(record, world, labels, set())
    assert folder.map_path.read_bytes()[:4] == b"\x89PNG"
