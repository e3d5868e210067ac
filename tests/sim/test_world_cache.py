"""The world cache (``sim.world_cache``): a world read back is the world built, built once per code and input;
other code, another scene file, a broken file or ``off`` never hand out a stale or no world."""

from __future__ import annotations

import logging
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from more_agent.eval.episode import run_episode
from more_agent.records import EpisodeSpec
from more_agent.sim import world_cache
from more_agent.sim.instantiate import TaskInstance
from more_agent.sim.world_cache import ENV_WORLD_CACHE, instantiate_cached, summary_cached, world_cache_path

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"


@pytest.fixture
def cache_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "cache" / "worlds.sqlite"
    monkeypatch.setenv(ENV_WORLD_CACHE, str(path))
    return path


@pytest.fixture
def builds(monkeypatch: pytest.MonkeyPatch) -> list[tuple]:
    """The arguments of every world actually built (not read from the cache)."""
    from more_agent.sim import instantiate as module

    made: list[tuple] = []
    real = module.instantiate

    def counting(*args, **kwargs):
        made.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(module, "instantiate", counting)
    return made


def _signature(instance: TaskInstance) -> tuple:
    world = instance.world
    objects = sorted(
        (o.name, o.category, o.room, o.parent, o.relation, tuple(np.round(o.center, 9)), tuple(np.round(o.size, 9)))
        for o in world.objects.values()
    )
    robot = (world.robot.x, world.robot.y, world.robot.yaw)
    labels = {name: instance.labels.label(name) for name in world.objects}
    return objects, robot, instance.description, instance.scope, labels, instance.distractors, instance.start


def _rows(path: Path, table: str = "worlds") -> list[tuple[str, str]]:
    with sqlite3.connect(path) as connection:
        return connection.execute(f"SELECT key, fingerprint FROM {table}").fetchall()


def test_a_world_read_back_is_the_world_built_and_is_built_once_per_input(cache_file: Path, builds: list) -> None:
    first = instantiate_cached(TASK, str(KITCHEN), 0)
    again = instantiate_cached(TASK, str(KITCHEN), 0)
    assert len(builds) == 1 and again is not first and _signature(again) == _signature(first)
    other_seed = instantiate_cached(TASK, str(KITCHEN), 1)
    other_start = instantiate_cached(TASK, str(KITCHEN), 0, start="task-room")
    assert len(builds) == 3 and _signature(first) not in (_signature(other_seed), _signature(other_start))
    assert len(_rows(cache_file)) == 3


def test_an_episode_on_a_world_read_back_is_the_episode_on_the_world_built(cache_file: Path, builds: list) -> None:
    spec = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=2, planner="oracle")
    built, read = run_episode(spec), run_episode(spec)
    assert len(builds) == 1 and built.success
    assert read.model_dump(exclude={"timings"}) == built.model_dump(exclude={"timings"})


def test_other_code_builds_anew_and_its_worlds_replace_the_old(
    cache_file: Path, builds: list, monkeypatch: pytest.MonkeyPatch
) -> None:
    instantiate_cached(TASK, str(KITCHEN), 0)
    monkeypatch.setattr(world_cache, "code_fingerprint", lambda: "other code")
    instantiate_cached(TASK, str(KITCHEN), 0)
    instantiate_cached(TASK, str(KITCHEN), 0)
    assert len(builds) == 2
    assert [fingerprint for _, fingerprint in _rows(cache_file)] == ["other code"]


def test_a_summary_is_made_once_from_the_world_cached_and_again_for_other_kinds_rows_or_code(
    cache_file: Path, builds: list, monkeypatch: pytest.MonkeyPatch
) -> None:
    world = instantiate_cached(TASK, str(KITCHEN), 0)
    seen: list[tuple] = []

    def summarize(instance: TaskInstance) -> dict[str, object]:
        seen.append(_signature(instance))
        return {"description": instance.description, "scope": instance.scope}

    first = summary_cached("test", TASK, str(KITCHEN), 0, summarize)
    assert summary_cached("test", TASK, str(KITCHEN), 0, summarize) == first
    assert first["description"] == world.description and seen == [_signature(world)] and len(builds) == 1
    summary_cached("another", TASK, str(KITCHEN), 0, summarize)
    summary_cached("test", TASK, str(KITCHEN), 1, summarize)
    assert len(seen) == 3 and len(builds) == 2  # another kind is made again; another seed builds its world
    with sqlite3.connect(cache_file) as connection:
        connection.execute("UPDATE summaries SET summary = 'not json'")
    assert summary_cached("test", TASK, str(KITCHEN), 0, summarize) == first and len(seen) == 4
    monkeypatch.setattr(world_cache, "code_fingerprint", lambda: "other code")
    assert summary_cached("test", TASK, str(KITCHEN), 0, summarize) == first and len(seen) == 5 and len(builds) == 3
    assert {fingerprint for _, fingerprint in _rows(cache_file, "summaries") + _rows(cache_file)} == {"other code"}


def test_a_scene_file_that_changed_builds_anew(cache_file: Path, builds: list, tmp_path: Path) -> None:
    scene = tmp_path / "kitchen.json"
    scene.write_bytes(KITCHEN.read_bytes())
    instantiate_cached(TASK, str(scene), 0)
    scene.write_bytes(KITCHEN.read_bytes() + b"\n")
    instantiate_cached(TASK, str(scene), 0)
    assert len(builds) == 2


def test_a_broken_cache_costs_no_world(cache_file: Path, builds: list, caplog: pytest.LogCaptureFixture) -> None:
    cache_file.parent.mkdir(parents=True)
    cache_file.write_bytes(b"not a sqlite file" * 100)
    with caplog.at_level(logging.WARNING, logger=world_cache.__name__):
        instance = instantiate_cached(TASK, str(KITCHEN), 0)
    assert isinstance(instance, TaskInstance) and len(builds) == 1
    assert "unreadable" in caplog.text and "not written" in caplog.text
    cache_file.unlink()
    instantiate_cached(TASK, str(KITCHEN), 0)
    with sqlite3.connect(cache_file) as connection:
        connection.execute("UPDATE worlds SET instance = ?", (b"garbage",))
    assert _signature(instantiate_cached(TASK, str(KITCHEN), 0)) == _signature(instance)  # built again, rewritten
    assert len(builds) == 3 and _signature(instantiate_cached(TASK, str(KITCHEN), 0)) == _signature(instance)
    assert len(builds) == 3


def test_off_builds_every_world_and_writes_nothing(
    tmp_path: Path, builds: list, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(ENV_WORLD_CACHE, "off")
    monkeypatch.setattr(world_cache, "DEFAULT_WORLD_CACHE", tmp_path / "default.sqlite")  # where it would write
    instantiate_cached(TASK, str(KITCHEN), 0)
    instantiate_cached(TASK, str(KITCHEN), 0)
    assert len(builds) == 2 and world_cache_path() is None and not list(tmp_path.rglob("*.sqlite"))


def test_the_cache_file_is_named_by_the_environment_else_the_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV_WORLD_CACHE, raising=False)
    assert world_cache_path() == world_cache.DEFAULT_WORLD_CACHE
    monkeypatch.setenv(ENV_WORLD_CACHE, "~/worlds.sqlite")
    assert world_cache_path() == Path.home() / "worlds.sqlite"
