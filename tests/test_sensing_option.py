"""``--sensing``: the cadence travels like the perception mode (spec, record, run config, resume key, folder
name), records and runs of older versions read as the cadence they ran with, and it reaches the planner's
embodiment."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from pydantic import ValidationError
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.errors import UserError
from more_agent.eval.episode import reset_planner
from more_agent.eval.report_html import episode_file
from more_agent.eval.store import RunConfig, check_same_run, episode_dirname, pending, read_run_config
from more_agent.eval.worker import execute_episode
from more_agent.planners.base import make_planner
from more_agent.records import RECORD_SCHEMA_VERSION, EpisodeRecord, EpisodeSpec
from more_agent.sensing_spec import DEFAULT_SENSING, SensingCadence, parse_sensing
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.scene import load_scene

KITCHEN = Path(__file__).parent / "fixtures" / "tasks_kitchen_scene.json"
FAKE = ["--episode-fn", "tests.eval.fake_episodes:deterministic_episode", "--no-progress"]
runner = CliRunner()


def test_the_text_is_canonical_and_a_bad_one_is_one_error_with_an_example() -> None:
    assert DEFAULT_SENSING == "1m/45deg" == SensingCadence().text()
    assert parse_sensing(" 0.50 m / 30 deg ") == SensingCadence(distance_m=0.5, angle_deg=30.0)
    assert EpisodeSpec(task="t").sensing == "1m/45deg"
    assert EpisodeSpec(task="t", sensing="0.50m/30.0deg").sensing == "0.5m/30deg"
    with pytest.raises(UserError, match=r"write DISTANCEm/ANGLEdeg, e\.g\. 1m/45deg"):
        parse_sensing("0.5/30")
    for bad in ("1m/70deg", "0m/30deg", "1.2.3m/30deg"):
        with pytest.raises(UserError, match="field of view"):
            parse_sensing(bad)
    with pytest.raises(ValidationError, match="DISTANCEm/ANGLEdeg"):
        EpisodeSpec(task="t", sensing="fast")


def test_the_cadence_at_least_as_often_as_two_takes_the_shorter_distance_and_angle() -> None:
    finer = parse_sensing("1m/20deg").at_least_as_often_as(parse_sensing("0.5m/30deg"))
    assert finer.text() == "0.5m/20deg"


def test_records_and_runs_of_older_versions_read_as_the_cadence_they_ran_with(tmp_path: Path) -> None:
    assert EpisodeRecord.for_spec(EpisodeSpec(task="t", sensing="2m/20deg")).sensing == "2m/20deg"
    old = EpisodeRecord.model_validate({"schema_version": 5, "task": "t", "scene": "s", "seed": 0, "planner": "oracle"})
    assert (old.sensing, old.schema_version) == ("0.5m/30deg", RECORD_SCHEMA_VERSION)
    (tmp_path / "run.json").write_text(json.dumps({"planner": "oracle", "episode_fn": "m:f"}))
    config = read_run_config(tmp_path)
    assert config is not None and config.sensing == "0.5m/30deg"


def test_resume_key_and_folder_name_tell_the_cadences_apart(tmp_path: Path) -> None:
    legacy = EpisodeSpec(task="a", sensing="0.5m/30deg")
    done = [EpisodeRecord.for_spec(EpisodeSpec(task="a", scene="Rs_int"))]
    assert pending([legacy], done) == [legacy] and pending([EpisodeSpec(task="a")], done) == []
    assert episode_dirname("a", None, 0, "grounded", sensing="0.5m/30deg") == "a__auto__s0__grounded__sensing-0.5m-30deg"
    assert episode_dirname("a", None, 0, "grounded") == "a__auto__s0__grounded"
    run = RunConfig(planner="grounded", tasks=["a"], seeds=[0], episode_fn="m:f")
    with pytest.raises(UserError, match="sensing: '1m/45deg' -> '0.5m/30deg'"):
        check_same_run(tmp_path, run, run.model_copy(update={"sensing": "0.5m/30deg"}))


def test_a_report_finds_the_files_of_an_episode_written_before_the_cadence_was_in_folder_names(tmp_path: Path) -> None:
    old = EpisodeRecord.model_validate({"schema_version": 5, "task": "a", "scene": "s", "seed": 0, "planner": "more"})
    folder = tmp_path / "episodes" / episode_dirname("a", "s", 0, "more")  # as those versions named it
    folder.mkdir(parents=True)
    (folder / "map.png").write_bytes(b"png")
    assert episode_file(old, tmp_path, "map.png") == folder / "map.png"


def test_an_episode_of_a_run_before_the_option_keeps_its_files_when_one_of_today_takes_its_folder(
    tmp_path: Path,
) -> None:
    """--resume --allow-mixed on a run written before the cadence was in folder names: the new episode's folder is
    the old one's name, and the old episode's files move to the folder today's layout names for it."""
    old = EpisodeRecord.model_validate({"schema_version": 5, "task": "a", "scene": "s", "seed": 0, "planner": "more"})
    folder = tmp_path / "episodes" / episode_dirname("a", None, 0, "more")  # the old layout, scene 'auto'
    folder.mkdir(parents=True)
    (folder / "episode.json").write_text(old.model_dump_json())
    (folder / "map.png").write_bytes(b"old map")
    spec = EpisodeSpec(task="a", planner="more")
    assert execute_episode("tests.eval.fake_episodes:folder_writing_episode", spec, str(tmp_path)).error is None
    moved = episode_file(old, tmp_path, "map.png")
    assert moved is not None and moved.read_bytes() == b"old map" and "sensing-0.5m-30deg" in moved.parent.name
    assert EpisodeRecord.model_validate_json((folder / "episode.json").read_text()).sensing == DEFAULT_SENSING
    assert not (folder / "map.png").exists()
    rerun = execute_episode("tests.eval.fake_episodes:folder_writing_episode", spec, str(tmp_path))
    assert rerun.error is None and sorted(p.name for p in (tmp_path / "episodes").iterdir()) == sorted(
        [folder.name, moved.parent.name]
    )  # the same episode run again replaces its own files, nothing moves


def test_a_bad_value_fails_first_and_a_resumed_run_must_keep_its_cadence(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(
        app, ["run", "putting_shopping_away", "--planner", "oracle", "--out", str(out), "--sensing", "1m/90deg"]
    )
    assert result.exit_code == 2 and "field of view" in result.output and not out.exists()
    first = ["eval", "--tasks", "a,b", "--planner", "oracle", "--out", str(out), *FAKE]
    result = runner.invoke(app, [*first, "--sensing", "0.5m/30deg"])
    assert result.exit_code == 0, result.output
    assert json.loads((out / "run.json").read_text())["sensing"] == "0.5m/30deg"
    result = runner.invoke(app, [*first, "--resume"])
    assert result.exit_code == 2 and "sensing: '0.5m/30deg' -> '1m/45deg'" in result.output


def test_the_episodes_cadence_reaches_the_planners_embodiment() -> None:
    kitchen = instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0, start="task-room")
    agent = make_planner("grounded")
    cadence = SensingCadence(distance_m=0.25, angle_deg=20.0)
    reset_planner(agent, kitchen, GoalChecker(kitchen), sensing=cadence)
    assert agent.body.schedule.cadence == cadence  # type: ignore[attr-defined]
