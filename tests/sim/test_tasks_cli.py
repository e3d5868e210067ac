"""``more-agent tasks list / show``: output and exit status 2 without traceback on bad names."""

from __future__ import annotations

from typer.testing import CliRunner

from more_agent.cli import app

runner = CliRunner()


def test_list_paper_set() -> None:
    result = runner.invoke(app, ["tasks", "list", "--set", "more-paper"])
    assert result.exit_code == 0, result.output
    assert "putting_shopping_away" in result.output and "55 tasks" in result.output


def test_list_unknown_set_exits_2() -> None:
    result = runner.invoke(app, ["tasks", "list", "--set", "paper"])
    assert result.exit_code == 2
    assert "Traceback" not in result.output


def test_show_task_as_defined_without_placing_it() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shopping_away"])
    assert result.exit_code == 0, result.output
    assert "(inside ?pack__of__ground_beef.n.01_1" in result.output and "$electric_refrigerator.n.01_1" in result.output
    assert "pack__of__ground_beef.n.01_1" in result.output and "inside sack.n.01_1" in result.output
    assert "instantiated in" not in result.output and "--seed N or --scene S" in result.output


def test_show_task_with_a_seed_places_it_in_a_scene() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shopping_away", "--seed", "0"])
    assert result.exit_code == 0, result.output
    assert "instantiated in" in result.output and "fridge A" in result.output
    assert "(inside ?pack__of__ground_beef.n.01_1" in result.output
    assert "no state meets this goal" not in result.output


def test_show_says_when_no_state_meets_the_goal() -> None:
    result = runner.invoke(app, ["tasks", "show", "stacking_wood", "--seed", "0"])
    assert result.exit_code == 0, result.output
    assert "no state meets this goal" in result.output and "instantiated in" in result.output
    listed = runner.invoke(app, ["tasks", "list", "--set", "more-paper"])
    row = next(line for line in listed.output.splitlines() if line.startswith("stacking_wood"))
    assert row.split()[3:5] == ["yes", "no"]  # instantiable, and no state meets its goal


def test_show_unknown_task_exits_2_with_closest_names() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shoping_away"])
    assert result.exit_code == 2
    assert "putting_shopping_away" in result.output and "Traceback" not in result.output


def test_show_in_unsuitable_scene_exits_2_naming_the_candidates() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shopping_away", "--scene", "gates_bedroom"])
    assert result.exit_code == 2
    assert "does not suit" in result.output and "Beechwood_0_int" in result.output
    assert "Traceback" not in result.output


def test_show_lists_the_scenes_episodes_draw_from() -> None:
    result = runner.invoke(app, ["tasks", "show", "putting_shopping_away", "--seed", "1"])
    assert result.exit_code == 0, result.output
    assert "episode scenes" in result.output and "drawn for seed 1:" in result.output
