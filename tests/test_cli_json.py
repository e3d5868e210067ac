"""``--json`` of ``tasks list / show``, ``scene list / show`` and ``report``: the documented keys
(docs/cli-json.md), values that agree with the tables, and which modules the listing commands import."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from tests.eval.test_report import make_run, rec

runner = CliRunner()
KITCHEN = Path(__file__).parent / "fixtures" / "tasks_kitchen_scene.json"


def _json(args: list[str]) -> object:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_tasks_list_json_has_the_documented_keys() -> None:
    rows = _json(["tasks", "list", "--set", "more-paper"])
    assert len(rows) == 55
    assert set(rows[0]) == {"task", "n_objects", "n_goal_literals", "instantiable", "satisfiable", "scenes"}
    row = next(r for r in rows if r["task"] == "putting_shopping_away")
    assert row["instantiable"] is True and row["satisfiable"] is True and row["n_goal_literals"] > 0 and row["scenes"]
    assert [r["task"] for r in rows if r["satisfiable"] is False] == ["stacking_wood"]
    assert len(_json(["tasks", "list"])) == 1016


def test_tasks_show_json_names_the_instance() -> None:
    out = _json(["tasks", "show", "putting_shopping_away"])
    assert set(out) == {"task", "suitable_scenes", "episode_scenes", "seed", "goal", "instance"}
    assert any(g.startswith("(inside ?pack__of__ground_beef.n.01_1") for g in out["goal"])
    inst = out["instance"]
    assert set(inst) == {"scene", "description", "objects", "unsupported_literals", "satisfiable"}
    assert inst["satisfiable"] is True
    assert inst["scene"] == out["episode_scenes"][0]
    fridge = next(o for o in inst["objects"] if o["scope"].startswith("electric_refrigerator"))
    assert set(fridge) == {"scope", "object", "label", "category", "relation", "parent", "room"}
    assert fridge["label"] == "fridge A"


def test_tasks_show_reads_the_world_run_drives_from_the_world_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The instance is the one ``run`` with that seed builds: built once into the world cache, then read from it."""
    monkeypatch.setenv("MORE_AGENT_WORLD_CACHE", str(tmp_path / "worlds.sqlite"))
    first = _json(["tasks", "show", "putting_shopping_away", "--seed", "1"])
    import more_agent.sim.instantiate as instantiate

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("built again instead of read from the world cache")

    monkeypatch.setattr(instantiate, "instantiate", refuse)
    assert _json(["tasks", "show", "putting_shopping_away", "--seed", "1"]) == first
    text = runner.invoke(app, ["tasks", "show", "putting_shopping_away", "--seed", "1"])
    assert text.exit_code == 0 and f"instantiated in {first['instance']['scene']} (seed 1; built in" in text.output


def test_a_second_tasks_show_reads_what_it_shows_without_the_modules_that_build_or_unpickle_a_world(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The world cache keeps what ``tasks show`` shows beside the world: numba, scipy and bddl's goal
    check (a second and a half) are not needed again."""
    monkeypatch.setenv("MORE_AGENT_WORLD_CACHE", str(tmp_path / "worlds.sqlite"))
    show = ["tasks", "show", "putting_shopping_away", "--scene", str(KITCHEN)]
    _json(show)  # the first show builds the world and checks its goal (in this process)
    for args in ([*show, "--json"], show):
        second = _imported(args)
        assert {m for m in second for slow in SLOW_IMPORTS if m == slow or m.startswith(slow + ".")} == set()
        assert not {"more_agent.sim.instantiate", "more_agent.sim.goals", "more_agent.sim.world", "scipy"} & second
    read_back = _json(show)
    monkeypatch.setenv("MORE_AGENT_WORLD_CACHE", "off")
    assert read_back == _json(show)  # what a show reads back is what it shows of a world built anew


def test_tasks_show_json_shows_a_goal_bddl_cannot_score() -> None:
    inst = _json(["tasks", "show", "make_a_bake_sale_stand_stall"])["instance"]  # no ground option for its goal
    assert inst["objects"] and inst["satisfiable"] is None


def test_tasks_show_json_keeps_the_clean_error() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shoping_away", "--json"])
    assert result.exit_code == 2 and "putting_shopping_away" in result.output and "Traceback" not in result.output


def test_scene_list_and_show_json() -> None:
    scenes = _json(["scene", "list"])
    assert len(scenes) == 51 and set(scenes[0]) == {"scene", "rooms"}
    assert "kitchen_0" in next(s for s in scenes if s["scene"] == "Rs_int")["rooms"]
    shown = _json(["scene", "show", "Rs_int", "--seed", "1"])
    assert set(shown) == {"scene", "seed", "n_doors", "n_windows", "n_furniture", "n_wall_boxes", "rooms"}
    assert shown["seed"] == 1 and {r["id"] for r in shown["rooms"]} == set(next(s for s in scenes if s["scene"] == "Rs_int")["rooms"])
    room = shown["rooms"][0]
    assert set(room) == {"id", "type", "area_m2", "ground", "outdoor", "doors", "furniture"} and room["area_m2"] > 0
    assert sum(sum(r["furniture"].values()) for r in shown["rooms"]) == shown["n_furniture"]
    assert all(set(d) == {"door", "to", "open"} for r in shown["rooms"] for d in r["doors"])


def test_report_json_has_table_i_per_system_and_task(tmp_path: Path) -> None:
    a = make_run(tmp_path / "a", [rec("t1", success=True), rec("t2")])
    b = make_run(tmp_path / "b", [rec("t1"), rec("t1", "oracle", success=True)])
    out = _json(["report", str(a), str(b), "--per-task"])
    assert set(out) == {"systems", "tasks", "dropped_duplicates"} and out["dropped_duplicates"] == 1
    more = next(s for s in out["systems"] if s["system"] == "more (openai:gpt-4o)")
    assert set(more) == {"system", "n", "n_tasks", "n_errors", "SR", "TTC", "TP", "rTP"}
    assert more["n"] == 2 and more["SR"]["mean"] == 0.5 and set(more["SR"]) == {"mean", "low", "high", "n", "method"}
    assert [(t["system"], t["task"]) for t in out["tasks"]] == [
        ("more (openai:gpt-4o)", "t1"), ("more (openai:gpt-4o)", "t2"), ("oracle", "t1")]


SLOW_IMPORTS = ("scipy.signal", "scipy.optimize", "matplotlib", "skimage.measure", "numba", "openai",
                "more_agent.eval.episode", "more_agent.llm.client", "more_agent.planners", "more_agent.mapping",
                "more_agent.records")
"""Modules a listing never needs (scipy.signal alone took a second, through skimage.measure; the episode
records' pydantic models a tenth of one)."""


def _imported(args: list[str]) -> set[str]:
    """The modules a fresh interpreter holds after running ``more-agent ARGS``."""
    code = ("import contextlib, io, json, sys\nfrom more_agent.cli import app\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n    app(sys.argv[1:], standalone_mode=False)\n"
            "print(json.dumps(sorted(sys.modules)))")
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, check=True,
                          cwd=Path(__file__).resolve().parents[1])
    return set(json.loads(done.stdout.splitlines()[-1]))


@pytest.mark.parametrize("args", [["--help"], ["tasks", "list"], ["scene", "list"], ["scene", "show", "Rs_int"],
                                  ["tasks", "show", "buy_eggs"]])
def test_listing_commands_import_only_what_they_use(args: list[str]) -> None:
    modules = _imported(args)
    assert "more_agent.cli" in modules
    assert {m for m in modules for slow in SLOW_IMPORTS if m == slow or m.startswith(slow + ".")} == set()
    if args[:2] != ["scene", "show"]:  # scene show generates the plan (scipy.ndimage, networkx)
        assert not any(m == "scipy" or m.startswith(("scipy.", "skimage", "networkx")) for m in modules)
    if args[:2] == ["tasks", "show"]:  # shown as defined: nothing instantiated, no world built
        assert not {"more_agent.sim.instantiate", "more_agent.sim.world", "more_agent.sim.scenes"} & modules


def test_eval_checks_its_arguments_and_writes_its_reports_without_the_simulator_or_plots(tmp_path: Path) -> None:
    """The episodes load what they need; the command around them checks --start without the start module
    (scipy.ndimage) and, with pictures off (the suite's setting), writes its reports without matplotlib."""
    modules = _imported(["eval", "--tasks", "t1,t2", "--planner", "oracle", "--out", str(tmp_path / "run"),
                         "--no-progress", "--episode-fn", "tests.eval.fake_episodes:deterministic_episode"])
    assert "more_agent.eval.report_writer" in modules and (tmp_path / "run" / "summary.md").exists()
    assert not {m for m in modules if m.startswith(("scipy.ndimage", "matplotlib", "more_agent.sim.start"))} - {
        "more_agent.sim.start_modes"}
