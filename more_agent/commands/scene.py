"""``more-agent scene ...``: list, show, generate and render BEHAVIOR-1K scenes (or a scene JSON file)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.markup import escape
from rich.table import Table

from more_agent.commands._common import (
    MAX_SEED,
    JsonOption,
    check_output_file,
    console,
    print_columns,
    print_json,
    user_errors_exit_2,
)

if TYPE_CHECKING:
    from more_agent.sim.scene import Scene

app = typer.Typer(help="BEHAVIOR-1K scenes: list, show, generate, render.", no_args_is_help=True)

SCENE_ARG = typer.Argument(..., help="Scene name (e.g. Rs_int) or a path to a scene .json file.")
SEED_OPT = typer.Option(0, "--seed", min=0, max=MAX_SEED, help="Layout seed; same scene and seed give the same plan.")


@app.command("list")
@user_errors_exit_2
def list_(as_json: JsonOption = False) -> None:
    """List the 51 BEHAVIOR-1K scenes with their rooms."""
    from more_agent.sim import catalog

    if as_json:
        print_json([{"scene": name, "rooms": list(catalog.scene_rooms(name))} for name in catalog.scene_names()])
        return
    names = catalog.scene_names()
    rows = []
    for name in names:
        rooms = list(catalog.scene_rooms(name))
        rows.append([name, str(len(rooms)), ", ".join(rooms)])
    print_columns(f"{len(names)} scenes", ["scene", "rooms", "room ids"], rows)


@app.command("show")
@user_errors_exit_2
def show(scene: str = SCENE_ARG, seed: int = SEED_OPT, as_json: JsonOption = False) -> None:
    """Rooms (type, area, ground, doors), doors and furniture counts of a generated plan."""
    from more_agent.sim.scenes import get_scene

    s = get_scene(scene, seed)
    if as_json:
        print_json(_show_json(s))
        return
    console.print(
        f"[bold]{escape(s.name)}[/] seed {s.seed}: {len(s.rooms)} rooms, {len(s.doors)} doors, "
        f"{len(s.windows)} windows, {len(s.furniture)} furniture, {len(s.walls)} wall boxes"
    )
    rooms = Table("room", "type", "area m²", "ground", "outdoor", "doors to", "furniture")
    for r in s.rooms:
        area = (r.bounds[2] - r.bounds[0]) * (r.bounds[3] - r.bounds[1])
        links = [
            f"{d.id}:{next(x for x in d.rooms if x != r.id)}{'' if d.open else ' (closed)'}"
            for d in s.doors
            if r.id in d.rooms
        ]
        counts = Counter(f.category for f in s.furniture if f.room == r.id)
        cells = (
            r.id,
            r.type,
            f"{area:.1f}",
            r.ground,
            "yes" if r.outdoor else "",
            ", ".join(links),
            ", ".join(f"{c}×{n}" if n > 1 else c for c, n in sorted(counts.items())),
        )
        rooms.add_row(*map(escape, cells))  # a hand-written scene file may hold any text
    console.print(rooms)


def _show_json(s: Scene) -> dict[str, object]:
    """What ``scene show --json`` prints (keys in docs/cli-json.md)."""
    rooms = []
    for r in s.rooms:
        counts = Counter(f.category for f in s.furniture if f.room == r.id)
        rooms.append(
            {
                "id": r.id,
                "type": r.type,
                "area_m2": round((r.bounds[2] - r.bounds[0]) * (r.bounds[3] - r.bounds[1]), 3),
                "ground": r.ground,
                "outdoor": r.outdoor,
                "doors": [
                    {"door": d.id, "to": next(x for x in d.rooms if x != r.id), "open": d.open}
                    for d in s.doors
                    if r.id in d.rooms
                ],
                "furniture": dict(sorted(counts.items())),
            }
        )
    return {
        "scene": s.name,
        "seed": s.seed,
        "n_doors": len(s.doors),
        "n_windows": len(s.windows),
        "n_furniture": len(s.furniture),
        "n_wall_boxes": len(s.walls),
        "rooms": rooms,
    }


@app.command("generate")
@user_errors_exit_2
def generate(
    scene: str = SCENE_ARG,
    seed: int = SEED_OPT,
    out: Path = typer.Option(..., "--out", help="Where to write the scene JSON."),
) -> None:
    """Write a generated plan as scene JSON (the format a user can also write by hand)."""
    from more_agent.sim.scene import save_scene
    from more_agent.sim.scenes import get_scene

    check_output_file(out)
    save_scene(get_scene(scene, seed), out)
    console.print(f"wrote {out}", highlight=False, markup=False, soft_wrap=True)  # a path is never broken


@app.command("render")
@user_errors_exit_2
def render(
    scene: str = SCENE_ARG,
    seed: int = SEED_OPT,
    out: Path = typer.Option(..., "--out", help="Where to write the PNG."),
    labels: bool = typer.Option(False, "--labels", help="Write furniture ids on the plan."),
) -> None:
    """Draw the plan: rooms labelled, ground classes, walls, windows, open / closed doors, furniture.

    OUT without a suffix gets ``.png``; the line printed names the file written.
    """
    from more_agent.sim.scenes import get_scene
    from more_agent.viz.plan import plot_plan

    path = out if out.suffix else out.with_suffix(".png")
    check_output_file(path)
    written = plot_plan(get_scene(scene, seed), path, label_furniture=labels)
    console.print(f"wrote {written}", highlight=False, markup=False, soft_wrap=True)
