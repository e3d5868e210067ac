"""What bddl's generated data says about BEHAVIOR-1K scenes and object categories.

Reads ``bddl/generated_data``: ``combined_room_object_list.json`` (51 scenes -> rooms -> object
'category-model' counts) and ``object_inventory.json`` (bounding-box sizes per model id, in metres,
axis order x, y, z with z up), and bddl's ``ObjectTaxonomy`` (category -> synset -> abilities).
Everything is loaded lazily on first use and cached; nothing is read at import time.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import os
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from more_agent.errors import unknown_name_error

log = logging.getLogger(__name__)

Vec3 = tuple[float, float, float]


def _data_dir() -> str:
    import bddl

    return os.path.join(os.path.dirname(bddl.__file__), "generated_data")


@cache
def _room_lists() -> dict[str, dict[str, dict[str, int]]]:
    with open(os.path.join(_data_dir(), "combined_room_object_list.json")) as f:
        return json.load(f)["scenes"]


@cache
def _inventory() -> dict:
    """``object_inventory.json`` (3 MB), read once."""
    with open(os.path.join(_data_dir(), "object_inventory.json")) as f:
        return json.load(f)


@cache
def _model_sizes() -> dict[str, Vec3]:
    raw = _inventory()["bounding_box_sizes"]
    return {model: (float(s[0]), float(s[1]), float(s[2])) for model, s in raw.items()}


@cache
def _category_models() -> dict[str, list[str]]:
    """Category -> model ids, from the inventory's 'providers' keys ('category-model')."""
    out: dict[str, list[str]] = {}
    for key in _inventory()["providers"]:
        category, model = key.rsplit("-", 1)
        out.setdefault(category, []).append(model)
    return out


@cache
def taxonomy():  # -> bddl.object_taxonomy.ObjectTaxonomy
    """bddl's ObjectTaxonomy, built once on first use (about 0.3 s)."""
    from bddl.object_taxonomy import ObjectTaxonomy

    return ObjectTaxonomy()


@cache
def activity_names() -> tuple[str, ...]:
    """All 1016 activity names bddl ships (its definition folders), sorted; read without
    ``bddl.activity``, which imports networkx."""
    from bddl.config import ACTIVITY_CONFIGS_PATH

    return tuple(sorted(p.name for p in Path(ACTIVITY_CONFIGS_PATH).iterdir() if p.is_dir()))


@cache
def _domain_name() -> str:
    from bddl.parsing import parse_domain

    name: str = parse_domain("omnigibson")[0]
    return name


def activity_problem(name: str) -> tuple[dict[str, list[str]], list[Any], list[Any]]:
    """Activity ``name``'s problem 0 as bddl's parser reads it: (synset -> scopes, init, goal). The parser
    prints what it skips to stdout (a stray backslash in wash_a_baseball_cap, once in every episode's
    output before); that goes to a debug log line instead."""
    from bddl.parsing import parse_problem

    with contextlib.redirect_stdout(io.StringIO()) as said:
        _, objects, init, goal = parse_problem(name, 0, _domain_name())
    if skipped := said.getvalue().strip():
        log.debug("bddl on %s: %s", name, skipped)
    return objects, init, goal


def scene_names() -> list[str]:
    """The 51 BEHAVIOR-1K scene names, sorted."""
    return sorted(_room_lists())


def scene_rooms(name: str) -> dict[str, dict[str, int]]:
    """Room id -> {'category-model': count} for a scene, in bddl's room order (a fresh copy)."""
    rooms = _room_lists().get(name)
    if rooms is None:
        raise unknown_name_error("scene", name, scene_names())
    return {room: dict(objs) for room, objs in rooms.items()}


def categories_in_scene(name: str) -> list[str]:
    """Every object category listed in a scene's rooms (structural ones included), sorted."""
    return sorted({key.rsplit("-", 1)[0] for objs in scene_rooms(name).values() for key in objs})


def model_size(model: str) -> Vec3 | None:
    """Bounding-box extents (sx, sy, sz) in metres of one model id, or None if the inventory lacks it."""
    return _model_sizes().get(model)


def sized_categories() -> list[str]:
    """Every category with at least one sized model in the inventory, sorted."""
    sizes = _model_sizes()
    return sorted(c for c, models in _category_models().items() if any(m in sizes for m in models))


def has_model(category: str) -> bool:
    """Whether a sized model is of ``category``: whether a world can hold one (not 'checkout', 'cabinet')."""
    return category in _sized_set()


@cache
def _sized_set() -> frozenset[str]:
    """:func:`sized_categories` as a set, built once."""
    return frozenset(sized_categories())


@cache
def category_size(category: str) -> Vec3:
    """Median bounding-box extents (sx, sy, sz) in metres over a category's models.

    Covers every category in the object inventory (furniture and task objects alike); an unknown
    category raises a UserError naming the closest known ones.
    """
    sizes = _model_sizes()
    found = [sizes[m] for m in _category_models().get(category, []) if m in sizes]
    if not found:
        raise unknown_name_error("object category", category, sized_categories())
    med = np.median(np.asarray(found), axis=0)
    return (float(med[0]), float(med[1]), float(med[2]))


@cache
def _category_to_synsets() -> dict[str, tuple[str, ...]]:
    """Inverse of the taxonomy's synset -> categories, built once (its own lookup scans every synset)."""
    tax = taxonomy()
    out: dict[str, list[str]] = {}
    for synset in sorted(tax.taxonomy.nodes):
        for category in tax.get_categories(synset):
            out.setdefault(category, []).append(synset)
    return {c: tuple(s) for c, s in out.items()}


def category_synsets(category: str) -> list[str]:
    """The synset(s) a category belongs to (one in bddl 3.6), or [] if the taxonomy lacks it."""
    return list(_category_to_synsets().get(category, ()))


def synset_categories(synset: str) -> list[str]:
    """Categories whose objects count as ``synset``: its own and its descendants', sorted ([] if unknown)."""
    tax = taxonomy()
    if not tax.is_valid_synset(synset):
        return []
    return sorted(tax.get_subtree_categories(synset))


@cache
def has_ability(category: str, ability: str) -> bool:
    """True if one of the category's synsets has the BEHAVIOR-1K taxonomy ability (``openable``, ``cloth``, ...)."""
    tax = taxonomy()
    return any(tax.has_ability(s, ability) for s in category_synsets(category))


def is_openable(category: str) -> bool:
    """True if the category opens (fridge, cabinets, car, ...)."""
    return has_ability(category, "openable")


def is_cloth(category: str) -> bool:
    """True for cloth (garments, towels, sheets): it folds and crumples."""
    return has_ability(category, "cloth")


def is_attachable(category: str) -> bool:
    """True if the category attaches to another attachable thing ('attachable': a camera to a tripod)."""
    return has_ability(category, "attachable")


def can_hold_things(category: str) -> bool:
    """True if things can be put inside (the 'fillable' ability: cabinets, fridge, car; not a laptop)."""
    return has_ability(category, "fillable")


def is_scene_fixture(category: str) -> bool:
    """True if BEHAVIOR-1K marks it a scene object ('sceneObject': car, fridge, shopping cart, bathtub):
    part of a scene, never picked up."""
    return has_ability(category, "sceneObject")


# --- Which listed objects become scene furniture (our decision, documented in docs/scenes.md) ---

SKIPPED_CATEGORIES: frozenset[str] = frozenset(
    """floors ceilings walls roof baseboard structural_element background pillar stairs railing rail_fence
    stone_wall lawn driveway paver greenery door sliding_door garage_door elevator_door gate window
    openable_window fixed_window window_blind electric_switch wall_socket fire_alarm fire_sprinkler
    security_camera motion_sensor downlight room_light rectangular_light square_light track_light spotlight
    wall_mounted_light chandelier ceiling_fan ceiling_air_conditioner ceiling_mounted_projector
    ceiling_mounted_basketball_hoop ceiling_rack room_ventilator radiator picture painting portrait mirror
    wall_clock wall_nail hook wall_mounted_tv wall_mounted_loudspeaker wall_mounted_soap_dispenser
    whiteboard blackboard periodic_table information_bulletin decorative_sign grocery_sign signpost
    hanging_banners hanging fairy_light projection_screen towel_rack toilet_paper_dispenser
    toilet_paper_holder paper_towel_dispenser hand_dryer tissue_dispenser soap_dispenser
    shampoo_dispenser conditioner_dispenser isopropanol_dispenser showerhead hanging_plant vine
    low_resolution_tree scoreboard place_mat table_runner""".split()
)
"""Structural parts, fixtures, lights and wall decorations: the generator makes its own walls, doors
and windows, and a flat thing on a wall is nothing a robot puts objects in or on."""

WALL_MOUNTED_CATEGORIES: dict[str, float] = {"top_cabinet": 1.45, "shelf": 1.2}
"""Categories hung on a wall, with the height (m) of their bottom face."""

SURFACE_CATEGORIES: frozenset[str] = frozenset(
    """microwave monitor printer desktop_computer coffee_maker espresso_machine blender crock_pot
    food_slicer cash_register microscope laptop standing_tv table_lamp electric_mixer shredder
    magnetic_stirrer oden_cooker popcorn_machine beer_tap drink_dispenser jam_dispenser
    multi_station_tabletop_sink tabletop_sink drop_in_sink digital_scale projector sound_system globe
    burner""".split()
)
"""Appliances that stand on a counter, desk or table rather than on the floor."""

SUPPORT_CATEGORIES: frozenset[str] = frozenset(
    """countertop bottom_cabinet bottom_cabinet_no_top metal_bottom_cabinet desk breakfast_table
    coffee_table console_table pedestal_table conference_table commercial_kitchen_table lab_table
    checkout_counter reception_desk bar nightstand stand furniture_sink""".split()
)
"""Furniture whose top can carry a surface appliance (and task objects)."""

FREE_STANDING_CATEGORIES: frozenset[str] = frozenset(
    """breakfast_table coffee_table pedestal_table conference_table pool_table commercial_kitchen_table
    lab_table straight_chair swivel_chair armchair eames_chair rocking_chair garden_chair music_stool
    taboret ottoman car recreational_vehicle motorcycle tree bush garden_plant garden_umbrella
    garden_coffee_table garden_statue hammock pergola arbor playground swing swing_set sandbox
    wading_pool swimming_pool hot_tub massage_bed hospital_bed treadmill elliptical_machine exercise_bike
    bench_press_machine pommel_horse parallel_bars flat_bench gym_mat charcoal_grill shopping_cart
    serving_cart dish_rack_cart cubicle hammam_bench stadium_stand bicycle boulder""".split()
)
"""Floor furniture placed away from walls; every other floor piece goes against a wall first."""

VEHICLE_CATEGORIES: frozenset[str] = frozenset({"car", "recreational_vehicle", "motorcycle"})
"""Free-standing pieces that go on a garden's driveway (which the generator adds for them)."""

ROLE_CAPS: dict[str, int] = {"tree": 4, "bush": 8, "boulder": 4, "garden_plant": 6}
"""Most instances of a vegetation category kept per room (gardens list up to 64 trees)."""

MAX_PER_CATEGORY = 24
"""Most instances of any one category kept per room (a conference hall lists 700 chairs)."""

COUNTER_HEIGHT_M = 0.9
"""Countertops are listed as thin slabs; the generator makes them counters this tall."""


def furniture_role(category: str) -> str:
    """How the generator treats a listed category.

    'skip' (structural or too small: tasks add their own small objects), 'carpet' (a ground patch),
    'wall' (hung on a wall), 'surface' (stands on a support), 'free' (free-standing on the floor) or
    'floor' (on the floor against a wall).
    """
    if category in SKIPPED_CATEGORIES:
        return "skip"
    if category == "carpet":
        return "carpet"
    if category in WALL_MOUNTED_CATEGORIES:
        return "wall"
    if category in SURFACE_CATEGORIES:
        return "surface"
    if category == "countertop":
        return "floor"
    sx, sy, sz = category_size(category)
    big = (sx * sy >= 0.09 and sz >= 0.3) or sx * sy >= 0.5
    if not big:
        return "skip"
    return "free" if category in FREE_STANDING_CATEGORIES else "floor"


SURFACE_SYNSETS: frozenset[str] = frozenset(
    {
        "table.n.02",
        "carrel.n.02",
        "work_surface.n.01",
        "shelf.n.01",
        "bookcase.n.01",
        "grocery_shelf.n.01",
        "snack_rack.n.01",
        "cabinet.n.01",
        "bed.n.01",
        "hospital_bed.n.02",
        "sofa.n.01",
        "bench.n.01",
        "handcart.n.01",
        "free_weight_rack.n.01",
        "sink.n.01",
        "stove.n.01",
        "grill.n.02",
    }
)
"""Furniture whose top things are put on, by bddl synset and its descendants: tables and desks
(counters and office cubicles included), worktops, shelves, bookcases, cabinets, beds, sofas and
benches, carts, weight racks, sinks (basin and rim) and cooktops (stoves, grills). Not monitors,
lamps, plants, machines, bins, fixtures or the chairs one sits on: nobody leaves a keyboard on a
monitor or a book on a range hood."""


def descends_from(category: str, synsets: frozenset[str]) -> bool:
    """Whether one of the category's synsets is one of ``synsets`` or descends from one."""
    tax = taxonomy()
    return any(synsets & {s, *tax.get_ancestors(s)} for s in category_synsets(category))


@cache
def is_surface(category: str) -> bool:
    """Whether things are put on top of this furniture category (``SURFACE_SYNSETS``): tables,
    counters, shelves; where distractors go and where a searching robot looks for small items."""
    return descends_from(category, SURFACE_SYNSETS)
