"""``more-agent tasks list [--set NAME]`` and ``more-agent tasks show TASK [--scene S] [--seed N]``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from more_agent.commands._common import (
    MAX_SEED,
    JsonOption,
    console,
    print_columns,
    print_json,
    user_errors_exit_2,
)

if TYPE_CHECKING:
    from more_agent.sim.instantiate import TaskInstance
    from more_agent.sim.tasks import TaskDefinition

app = typer.Typer(help="BEHAVIOR-1K activities: list task sets, show one task.", no_args_is_help=True)


@app.command("list")
@user_errors_exit_2
def list_(
    set_: Annotated[str | None, typer.Option("--set", help="Task set: 'more-paper' or 'behavior-rearrange'.")] = None,
    as_json: JsonOption = False,
) -> None:
    """List tasks (all 1016 activities, or one task set) with objects, goal literals, status and scenes;
    'satisfiable: no' marks a goal no state meets (docs/tasks.md)."""
    from more_agent.sim.tasks import task_data, task_set

    data = task_data()["tasks"]
    names = task_set(set_) if set_ is not None else sorted(data)  # the package data holds every activity
    if as_json:
        print_json(
            [
                {
                    "task": name,
                    "n_objects": data[name]["n_objects"],
                    "n_goal_literals": data[name]["n_goal_literals"],
                    "instantiable": data[name]["instantiable"],
                    "satisfiable": data[name]["satisfiable"],
                    "scenes": data[name]["scenes"],
                }
                for name in names
            ]
        )
        return
    rows = []
    for name in names:
        e = data[name]
        scenes = e["scenes"]
        shown = ", ".join(scenes[:3]) + (f" (+{len(scenes) - 3})" if len(scenes) > 3 else "")
        met = {True: "yes", False: "no", None: "-"}[e["satisfiable"]]
        instantiable = "yes" if e["instantiable"] else "no"
        rows.append([name, str(e["n_objects"]), str(e["n_goal_literals"]), instantiable, met, shown or "-"])
    print_columns(
        f"{len(names)} tasks" + (f" in {set_}" if set_ else ""),
        ["task", "objects", "goal literals", "instantiable", "satisfiable", "scenes"],
        rows,
    )


@app.command("show")
@user_errors_exit_2
def show(
    task: Annotated[str, typer.Argument(help="Activity name, e.g. putting_shopping_away.")],
    scene: Annotated[
        str | None, typer.Option(help="Instantiate in this scene (implies instantiating; default seed 0).")
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            min=0,
            max=MAX_SEED,
            help="Instantiate with this seed (scene draw, scene generation, placement); without --seed or "
            "--scene the task is shown as defined, not placed. --json always instantiates (seed 0 by default).",
        ),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """Show a task: description, objects, goal and suitable scenes; with --seed or --scene, placed in a scene."""
    from more_agent.sim.tasks import EXCLUDED_SCENES, check_scene_suits, draw_scenes, load_task, suitable_scenes

    if as_json:
        print_json(_show_json(task, scene, seed or 0))
        return
    definition = load_task(task)
    scenes = suitable_scenes(task)
    console.print(task, style="bold", highlight=False, markup=False)
    console.print(f"suitable scenes ({len(scenes)}): {', '.join(scenes) or '-'}", highlight=False, markup=False)
    drawn = draw_scenes(task, seed or 0)
    console.print(
        f"episode scenes ({len(drawn)}, {', '.join(EXCLUDED_SCENES)} left out); "
        f"drawn for seed {seed or 0}: {drawn[0] if drawn else '-'}",
        highlight=False,
        markup=False,
    )
    if scene is not None:
        check_scene_suits(task, scene)
    _print_definition(definition)
    if seed is None and scene is None:
        if scenes:
            console.print("placed in a scene with --seed N or --scene S", highlight=False, markup=False)
        return
    if scenes or scene is not None:
        _print_instance(task, scene, seed or 0)


def _print_definition(definition: TaskDefinition) -> None:
    """The task as bddl defines it: description template, goal, and each scope with its init literals."""
    from more_agent.sim.tasks import category_phrase, literal_text

    if definition.paper_description is not None:
        console.print(f"paper description: {definition.paper_description}", highlight=False, markup=False)
    console.print("goal:", highlight=False)
    for lit in definition.goal:
        console.print(f"  {literal_text(lit)}", highlight=False, markup=False)
    table = Table(title="scopes (bddl init)")
    table.add_column("scope", no_wrap=True)
    table.add_column("what")
    table.add_column("initially")
    for synset, scopes in definition.objects.items():
        for s in scopes:
            init = [" ".join([lit[0], *lit[2:]]) for lit in definition.init if len(lit) > 1 and lit[1] == s]
            table.add_row(*map(escape, (s, category_phrase(synset), ", ".join(init) or "-")))
    console.print(table)


def _print_instance(task: str, scene: str | None, seed: int) -> None:
    """The task instantiated: its scene, description, whether any state meets its goal, and where each
    scope's object is: the world ``run`` with that seed drives (:func:`_instance_summary`)."""
    summary = _instance_summary(task, scene, seed)
    inst = summary["instance"]
    console.print(
        f"instantiated in {inst['scene']} (seed {seed}; built in {summary['built_s']:.2f} s)",
        highlight=False,
        markup=False,
    )
    console.print(f"description: {inst['description']}", highlight=False, markup=False)
    if inst["satisfiable"] is False:
        console.print(_UNSATISFIABLE, style="yellow", highlight=False, markup=False)
    table = Table(title="objects")
    for col in ("scope", "world object", "label", "category", "where"):
        table.add_column(col)
    for o in inst["objects"]:
        where = f"{o['relation']} {o['parent']}" if o["parent"] else o["room"] or ""
        table.add_row(*map(escape, (o["scope"], o["object"], o["label"], o["category"] or "-", where)))
    console.print(table)
    if inst["unsupported_literals"]:
        console.print(
            "init literals not modelled: " + ", ".join(inst["unsupported_literals"]), highlight=False, markup=False
        )


def _show_json(task: str, scene: str | None, seed: int) -> dict[str, object]:
    """What ``tasks show --json`` prints (keys in docs/cli-json.md); the instance as ``_print_instance`` reads it."""
    from more_agent.sim.tasks import (
        check_scene_suits,
        draw_scenes,
        literal_text,
        load_task,
        suitable_scenes,
    )

    definition = load_task(task)
    scenes, drawn = suitable_scenes(task), draw_scenes(task, seed)
    if scene is not None:
        check_scene_suits(task, scene)
    return {
        "task": task,
        "suitable_scenes": scenes,
        "episode_scenes": drawn,
        "seed": seed,
        "goal": [literal_text(lit) for lit in definition.goal],
        "instance": _instance_summary(task, scene, seed)["instance"] if scenes or scene is not None else None,
    }


def _instance_summary(task: str, scene: str | None, seed: int) -> dict[str, Any]:
    """What ``tasks show`` shows of the instance ``run`` with that seed drives: ``instance`` (the ``--json``
    keys) and ``built_s``. Kept in the world cache beside the world (``world_cache.summary_cached``), so a
    second show neither unpickles the world nor checks its goal again."""
    from more_agent.sim.world_cache import summary_cached

    return summary_cached("tasks-show", task, scene, seed, _summarize)


def _summarize(inst: TaskInstance) -> dict[str, Any]:
    objects = []
    for s, name in inst.scope.items():
        obj = inst.world.objects.get(name)
        objects.append(
            {
                "scope": s,
                "object": name,
                "label": inst.label(s),
                "category": obj.category if obj else None,
                "relation": obj.relation if obj else None,
                "parent": obj.parent if obj else None,
                "room": obj.room if obj else None,
            }
        )
    instance = {
        "scene": inst.scene,
        "description": inst.description,
        "objects": objects,
        "unsupported_literals": list(inst.unsupported_literals),
        "satisfiable": _satisfiable(inst),
    }
    return {"instance": instance, "built_s": inst.timings["total"]}


def _satisfiable(inst: TaskInstance) -> bool | None:
    """Whether any state meets the instance's goal (``GoalChecker.satisfiable``); None when bddl cannot
    score its goal at all (``GoalError``: make_a_bake_sale_stand_stall), which ``tasks show`` still shows."""
    from more_agent.sim.goals import GoalChecker, GoalError

    try:
        return GoalChecker(inst).satisfiable
    except GoalError:
        return None


_UNSATISFIABLE = "no state meets this goal: every episode of it fails, whatever the robot does (docs/tasks.md)"
"""What ``tasks show`` says of a goal that is unsatisfiable (``GoalChecker.satisfiable``)."""
