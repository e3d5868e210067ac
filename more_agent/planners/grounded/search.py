"""How the ``grounded`` planner looks for an object it has not seen (package docstring, point 4)."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import numpy as np

from more_agent.goal import Literal, TaskGoal
from more_agent.mapping import visible_unknown_area
from more_agent.planners.base import DONE, Step
from more_agent.planners.grounded.agenda import Agenda
from more_agent.planners.grounded.belief import Belief, bind, unseen
from more_agent.planners.grounded.situation import Situation
from more_agent.planners.grounded.steps import Choice, object_step, put_down
from more_agent.planners.room_types import OUTDOOR_ROOM_TYPES, furniture_rooms, is_furniture, listed_share
from more_agent.planners.targets import Area
from more_agent.planners.whereabouts import (
    container_prior,
    container_share,
    destination_share,
    never_inside,
    room_prior,
    together_share,
)
from more_agent.robot import XY
from more_agent.scene_graph import ObjectNode
from more_agent.sim.catalog import can_hold_things, category_size, has_model, is_scene_fixture, is_surface
from more_agent.vocabulary import RELATIONS, scope_synset

OPENS_BEFORE_EXPLORING = 3
"""Containers opened to look inside, one after the other, before the search explores again."""

FRUITLESS_EXPLORES = 2
"""A room whose last explores, this many in a row, revealed no new object and little new floor
(``belief.NEW_FLOOR_M2``) yields to containers, doors, other rooms."""

INFORMATIVE_SHARE = 0.75
"""Explore goes to the frontiers showing at least this share of the most unknown floor in sensor range ..."""

FAR_FRONTIER_SHARE = 0.5
"""... and of those, to the ones at least this share as far from the robot's path as the farthest one."""

GAIN_STEP_M2 = 5.0
"""Rooms whose frontiers show unseen floor within this many square metres of each other rank as equal
(the nearer first)."""

LIKELY_ROOM_SHARE = 0.1
"""A room type holding this share of the missing items' evidence is searched before rooms of unknown type ..."""

LIKELY_OF_TOP = 0.5
"""... when it also holds this share of what the likeliest room type holds."""

UNKNOWN_CONTAINER_SHARE = 0.05
"""How likely a container that fits holds an item the corpus never places in one of its kind."""

LOOK_AT_M = 2.0
"""Furniture of the task's rooms with a corner farther than this from everywhere the robot has been is
driven to when an item is missing."""


def search(belief: Belief, sit: Situation, agenda: Agenda, lit: Literal, held: str | None) -> Choice:
    """Look for an unseen object of ``lit``: the furniture the task's items were found on or are said to stay on
    (:func:`holders`), containers here, the likeliest unexplored room, other containers, closed doors (before a
    room of a type unlikely to hold the missing items: a car is outside), containers that cannot hold them
    (:func:`closed_containers`); give up when none is left. The containers
    here wait while a room of a likelier tier (:func:`room_tier`) is left to explore (cleaning_parks seed 1
    opened 18 kitchen cabinets for the bottles that lay on the lawn); those of a room of the last tier
    (``ELSEWHERE``: unlikely, and across the walls) while any room is left to explore or a door to open."""
    goal = agenda.goal
    missing = [
        s for s in lit.args if s != goal.robot and not goal.is_floor(s) and bind(belief, goal, s, sit.xy) is None
    ]
    note = f"looking for {', '.join(goal.named.get(s, s) for s in missing) or 'the room of ' + lit.text}"
    items = [s for s in missing if not is_furniture_scope(agenda, s)]
    searching_items = not missing or bool(items)
    mass = room_mass(agenda, missing, found_rooms(belief, agenda), destination_rooms(belief, agenda))
    closed, unlikely_containers = (
        closed_containers(belief, sit, agenda, items + other_missing_items(belief, agenda, items))
        if searching_items
        else ([], [])
    )
    rooms = task_rooms(belief, agenda)
    region = room_to_explore(belief, sit, agenda, missing, rooms, mass)
    doors = closed_doors(belief, sit)
    here_tier = room_tier(belief, sit.here, mass) if sit.here is not None else UNTYPED
    region_tier = room_tier(belief, region, mass) if region is not None else UNTYPED
    left = region is not None and not stale(belief, region)
    likelier = left and sit.here is not None and region_tier < here_tier
    holder = furniture_to_look_at(belief, sit, holders(belief, sit, agenda, missing)) if searching_items else None
    if holder is not None:
        return object_step(sit, "navigate", holder, note)
    if (
        closed
        and closed[0].region_id == sit.here
        and (belief.opened_in_a_row < OPENS_BEFORE_EXPLORING or region is None)
        and not likelier
        and not (here_tier == ELSEWHERE and (left or doors))
    ):
        return open_to_look(belief, sit, agenda, closed[0].label, held, note)
    if searching_items and (not left or region not in rooms):
        furniture = furniture_to_look_at(belief, sit, surfaces_of(sit, rooms))
        if furniture is not None:
            return object_step(sit, "navigate", furniture, note)
        in_task_rooms = [o for o in closed if o.region_id in rooms]
        if in_task_rooms:
            return open_to_look(belief, sit, agenda, in_task_rooms[0].label, held, note)
    unlikely = region is not None and region_tier >= UNLIKELY
    if region is not None and left and not (unlikely and doors):
        return explore_step(sit, region, note)
    for pool in (doors, closed) if unlikely or here_tier == ELSEWHERE else (closed, doors):  # the way out first
        if pool:
            return open_to_look(belief, sit, agenda, pool[0].label, held, note)
    if region is not None:
        return explore_step(sit, region, note)
    if unlikely_containers:
        return open_to_look(belief, sit, agenda, unlikely_containers[0].label, held, note)
    why = f"{note}: nothing left to explore or open"
    return Choice(Step(DONE, note=why, gave_up=f"grounded planner gave up {why}"))


def other_missing_items(belief: Belief, agenda: Agenda, items: Sequence[str]) -> list[str]:
    """The goal's other items not seen yet: a container worth opening for one of them is worth opening
    while looking for ``items`` (the book that may lie in the carton the documents are in)."""
    goal = agenda.goal
    scopes = dict.fromkeys(s for lit in agenda.literals for s in lit.args)
    return [
        s
        for s in scopes
        if s not in items
        and s != goal.robot
        and not goal.is_floor(s)
        and not is_furniture_scope(agenda, s)
        and unseen(belief, goal, s)
    ]


def closed_containers(
    belief: Belief, sit: Situation, agenda: Agenda, items: Sequence[str]
) -> tuple[list[ObjectNode], list[ObjectNode]]:
    """Closed containers that hold things, not looked into nor given up, split into those that may hold
    one of the missing ``items`` (:func:`container_likelihood`; the robot's room's first, likeliest first,
    then nearest) and the others (nearest first: opened only when nothing else is left)."""
    here = sit.here
    candidates = [
        o
        for o in sit.graph.objects.values()
        if o.open is False
        and can_hold_things(o.category)
        and o.label not in belief.looked_into
        and o.label not in belief.dropped
    ]
    by_region: dict[str | None, list[str]] = {}  # the categories of each room's containers, open or closed
    for o in sit.graph.objects.values():
        if o.open is not None and can_hold_things(o.category):
            by_region.setdefault(o.region_id, []).append(o.category)
    like = {
        o.label: container_likelihood(agenda, o.category, items, by_region.get(o.region_id, ())) for o in candidates
    }
    likely = sorted(
        (o for o in candidates if like[o.label] > 0),
        key=lambda o: (o.region_id != here, -like[o.label], math.dist(o.position[:2], sit.xy), o.label),
    )
    others = sorted(
        (o for o in candidates if like[o.label] == 0), key=lambda o: (math.dist(o.position[:2], sit.xy), o.label)
    )
    return likely, others


def container_likelihood(agenda: Agenda, container: str, items: Sequence[str], siblings: Sequence[str] = ()) -> float:
    """How likely a closed ``container`` category holds one of the missing ``items`` (scopes), for the
    order containers are opened in: for an item that fits in it (catalog sizes: a suitcase is in no
    microwave) and that the corpus does not show as never kept inside anything
    (:func:`~more_agent.planners.whereabouts.never_inside`), ``UNKNOWN_CONTAINER_SHARE`` plus the share of
    its evidence inside such containers (:func:`~more_agent.planners.whereabouts.container_prior`), spread over
    the containers of its room (``siblings``: their categories, its own included); the largest over the items,
    0 when none may be inside. With no item named (looking for a room), any may."""
    if not items:
        return UNKNOWN_CONTAINER_SHARE
    best = 0.0
    activity = agenda.goal.activity
    for scope in items:
        synset = scope_synset(scope)
        if not fits(agenda.goal.categories.get(scope, frozenset()), container) or never_inside(synset, activity):
            continue
        share = container_share(container, container_prior(synset, activity), siblings)
        best = max(best, UNKNOWN_CONTAINER_SHARE + share)
    return best


def fits(categories: frozenset[str], container: str) -> bool:
    """Whether an object of one of ``categories`` fits in a ``container`` (sorted extents, catalog medians);
    True when a size is unknown."""
    if not has_model(container):
        return True
    room = sorted(category_size(container))
    item_sizes = [sorted(category_size(c)) for c in categories if has_model(c)]
    return not item_sizes or any(all(a <= b for a, b in zip(size, room)) for size in item_sizes)


def closed_doors(belief: Belief, sit: Situation) -> list[ObjectNode]:
    """Closed doors not given up, nearest first."""
    return sorted(
        (
            o
            for o in sit.graph.objects.values()
            if o.category == "door" and o.open is False and o.label not in belief.dropped
        ),
        key=lambda o: math.dist(o.position[:2], sit.xy),
    )


def is_furniture_scope(agenda: Agenda, scope: str) -> bool:
    """Whether ``scope`` is furniture: the goal does not move it and every category that counts as it
    is furniture. A missing table is in no cabinet and shows from afar, so the search neither opens
    containers nor drives along shelves for it."""
    cats = agenda.goal.categories.get(scope, frozenset())
    return scope not in agenda.goal.moved and bool(cats) and all(is_furniture(c) for c in cats)


def furniture_to_look_at(belief: Belief, sit: Situation, furniture: Sequence[ObjectNode]) -> str | None:
    """The nearest of ``furniture`` the robot has not been near (``LOOK_AT_M``): explore() clears a store's
    floor, but groceries on a far shelf show only from close by. None once the last drives revealed nothing."""
    if belief.fruitless_looks >= FRUITLESS_EXPLORES:
        return None
    candidates = [
        o
        for o in furniture
        if o.label not in belief.looked_at
        and o.label not in belief.dropped
        and _far_corner_gap(o, sit.path) > LOOK_AT_M
    ]
    return min(candidates, key=lambda o: (math.dist(o.position[:2], sit.xy), o.label)).label if candidates else None


def surfaces_of(sit: Situation, rooms: set[str]) -> list[ObjectNode]:
    """The furniture things are put on (tables, shelves, counters: ``sim.catalog.is_surface``) of ``rooms``."""
    return [o for o in sit.graph.objects.values() if o.region_id in rooms and o.open is None and is_surface(o.category)]


def holders(belief: Belief, sit: Situation, agenda: Agenda, missing: Sequence[str]) -> list[ObjectNode]:
    """The furniture (``is_surface``) the objects the goal moves were found on, and the furniture the
    description says a ``missing`` one stays on ("leave toolbox A on countertop A", ``TaskGoal.stays``): a
    task's items are set out together, often on one counter or table, and small ones show only from close by.
    Looked at before the room's containers are opened: outfit_a_basic_toolbox seed 3 found the toolbox on a
    utility room's counter and opened the room's dryer, washer and four cabinets for the drill, which lay on
    that counter; seed 2 opened six of them for the toolbox while the counter it stays on was in sight."""
    goal = agenda.goal
    labels = {belief.found_on.get(belief.bound.get(s, "")) for s in _moved(agenda)}
    labels |= {bind(belief, goal, goal.stays[s], sit.xy) for s in missing if s in goal.stays}
    return [o for o in sit.graph.objects.values() if o.label in labels and is_surface(o.category)]


def open_to_look(belief: Belief, sit: Situation, agenda: Agenda, label: str, held: str | None, note: str) -> Choice:
    """Open ``label`` to look inside (freeing the hand first)."""
    if held is not None:
        return put_down(belief, sit, agenda, held)
    return Choice(object_step(sit, "go_to_and_open", label, note).action, looking=True)


def room_to_explore(
    belief: Belief,
    sit: Situation,
    agenda: Agenda,
    missing: list[str],
    rooms: set[str],
    mass: RoomMass | None = None,
) -> str | None:
    """The region with unexplored areas to explore next: rooms whose last explores revealed nothing
    new last; then by :func:`room_tier` for the missing objects (:func:`room_mass`: a room type where such
    items are kept or such furniture stands: a utility room before a lawn for tools; then rooms of a type
    not yet known; rooms of an unlikely type last); then by that mass (weeds are looked for on the lawn,
    not in the bathrooms that list the trash can they go in; beer and its fridge in a kitchen, not in
    the garden where beer is as often kept; not for a room of the last tier, ``ELSEWHERE``, whose share is
    below the mark anyway: cleaning_up_branches_and_twigs seed 1 explored a kitchen for 7 steps for the 2 %
    of branches the corpus leaves there while the lawn lay outside); then the room most likely to hold the
    missing furniture (by the share of the room type's listed objects it makes up,
    :func:`~more_agent.planners.room_types.listed_share`); then the rooms of the task's items found so far
    (``rooms``, from :func:`task_rooms`); then the room whose frontiers show the most unseen floor in
    sensor range (``GAIN_STEP_M2`` steps: a garden or a store is searched through, not left for a closet
    after a few metres, and a room nearly seen yields to one barely seen); then the nearest. ``mass``: the
    step's :func:`room_mass` when the caller has it."""
    cats = [c for s in missing for c in agenda.goal.categories.get(s, ()) if is_furniture(c)]
    if mass is None:
        mass = room_mass(agenda, missing, found_rooms(belief, agenda), destination_rooms(belief, agenda))
    open_regions = [rid for rid, r in sit.graph.regions.items() if r.frontiers]
    gain = unseen_floor(sit, open_regions)

    def score(rid: str) -> tuple[bool, int, float, float, bool, int, float, str]:
        kind = belief.room_types.get(rid)
        tier = room_tier(belief, rid, mass)
        weighed = tier != ELSEWHERE  # the last tier: by the floor it hides, not by the little it may hold
        like = max((listed_share(c, kind) for c in cats), default=0.0) if kind and weighed else 0.0
        return (
            stale(belief, rid),
            tier,
            -mass.get(kind or "", 0.0) if weighed else 0.0,
            -like,
            rid not in rooms,
            -round(gain[rid] / GAIN_STEP_M2),
            math.dist(sit.graph.regions[rid].centroid, sit.xy),
            rid,
        )

    return min(open_regions, key=score) if open_regions else None


LIKELY, UNTYPED, UNLIKELY, ACROSS, ELSEWHERE = 0, 1, 2, 3, 4
"""Room tiers for missing objects (:func:`room_tier`), searched in this order."""


class RoomMass(dict[str, float]):
    """Room type -> how many of the missing objects to expect there (:func:`room_mass`), and ``sides``: the sides
    of the walls (True: outdoors) where some missing object is likeliest, each by its own evidence: the car of
    packing_car_for_trip stands outdoors, its laptop and money are kept indoors."""

    def __init__(self, mass: dict[str, float], sides: frozenset[bool]) -> None:
        super().__init__(mass)
        self.sides = sides


def sides_of(mass: dict[str, float]) -> frozenset[bool]:
    """The sides of the walls (True: outdoors) holding the most of ``mass``: both on a tie, none when empty."""
    totals = {side: sum(n for k, n in mass.items() if (k in OUTDOOR_ROOM_TYPES) == side) for side in (False, True)}
    top = max(totals.values())
    return frozenset(side for side, n in totals.items() if n == top and n > 0)


def room_tier(belief: Belief, region: str, mass: RoomMass) -> int:
    """``LIKELY`` when the region's room type holds at least ``LIKELY_ROOM_SHARE`` of the missing objects
    (``mass``, :func:`room_mass`) and ``LIKELY_OF_TOP`` of the likeliest type's (bottles: kitchens, not the
    lawn that holds a fifth as many), ``UNLIKELY`` when its type is known and does not, ``UNTYPED`` when its
    type is unknown or nothing missing has evidence (``mass`` empty: every room as likely).

    A room on the other side of the walls from where every missing object is likeliest (outdoors when they all
    are indoors, or the other way round: ``RoomMass.sides``; a tie takes neither side) ranks after the unlikely
    rooms on their side: a likely one as ``ACROSS``, an unlikely one as ``ELSEWHERE``, last. The rooms still
    unseen that may hold the objects lie on that side, and a garden's frontiers lead to more lawn, not to the
    kitchen of the fridge: bringing_water seed 1 crossed a
    lawn for 22 steps, likely for bottles and coffee tables, while the living room and the kitchen lay behind
    doors not yet opened, and once they were open it crossed it again rather than explore the private office
    the kitchen lay behind. The lawn of a car is on the car's side (packing_car_for_trip seed 2 left it for the
    house's rooms, where the suitcases and the laptop are usually kept, and found none of them)."""
    kind = belief.room_types.get(region)
    if not mass or kind is None:
        return UNTYPED
    share, top = mass.get(kind, 0.0), max(mass.values())
    likely = share >= LIKELY_ROOM_SHARE and share >= LIKELY_OF_TOP * top
    if mass.sides and (kind in OUTDOOR_ROOM_TYPES) not in mass.sides:
        return ACROSS if likely else ELSEWHERE
    return LIKELY if likely else UNLIKELY


def room_mass(
    agenda: Agenda, missing: Sequence[str], found: Sequence[str] = (), placed: dict[str, str] | None = None
) -> RoomMass:
    """Room type -> how many of the ``missing`` objects to expect in a room of that type: where the missing
    items are kept (:func:`item_rooms`, one in all) plus, for each missing piece of furniture, the share of
    its kind standing in such rooms (:func:`~more_agent.planners.room_types.furniture_rooms`). Beer, kept as
    often in gardens as in kitchens, and the fridge it goes in: a kitchen; weeds and the trash can that bathrooms
    list: the lawn.

    What is known beats what is usual. An object the description says stays on a room's floor ("leave trash can
    A on the lawn"), or must leave it (``TaskGoal.leaves``, "no sod may remain on the garden floor": with no
    activity of the corpus placing sods, remove_sod seed 5 searched the house's rooms for 20 steps first), is in
    such a room. Once the task's items were ``found`` (room types, :func:`found_rooms`), or the description puts
    one of them there (the trash can on the lawn), the objects set out with them
    (items, and furniture that is no scene fixture: the weeds' trash can, not a fridge or a car) are where
    those were found with the probability that two items of one bddl activity share a room type
    (:func:`~more_agent.planners.whereabouts.together_share`, 0.98), and where they are usually kept otherwise:
    one activity placing branches in a kitchen is all the corpus says of branches, and bathrooms list more
    trash cans than gardens do. Before any is found, such furniture is where the missing items are likeliest,
    with that probability: the weeds' trash can on the lawn, not in the bathrooms that list trash cans
    (hoe_weeds seed 2). An item the goal puts into or onto a piece of furniture starts in that furniture's room
    with the share the corpus gives (:func:`delivered_rooms`; ``placed``: destination scope -> the room type it
    was found in). Where each missing object is likeliest, indoors or out, gives the mass's ``sides``
    (:func:`room_tier`)."""
    goal = agenda.goal
    stays = {s: kind for s in missing if (kind := goal.floor_rooms.get(goal.stays.get(s) or goal.leaves.get(s, "")))}
    stands = {s: furniture_rooms(goal.categories.get(s, ())) for s in missing if s not in goal.moved}
    stands = {s: rooms for s, rooms in stands.items() if rooms and s not in stays}  # a fridge: its kinds listed
    items = [s for s in missing if s not in stands and s not in stays]
    each_item = [(delivered_rooms(agenda, s, placed or {}), _set_out(goal, s)) for s in items]
    items_together = (mean_rooms([rooms for rooms, _ in each_item]), any(out for _, out in each_item))
    known = [*found, *(kind for s, kind in stays.items() if _set_out(goal, s))]
    together = {kind: n / len(known) for kind, n in Counter(known).items()}
    share = together_share()

    def beside(rooms: dict[str, float], lead: dict[str, float]) -> dict[str, float]:
        return {kind: share * lead.get(kind, 0.0) + (1 - share) * rooms.get(kind, 0.0) for kind in {*rooms, *lead}}

    def expected(rooms: dict[str, float], with_found: bool) -> dict[str, float]:
        return beside(rooms, together) if with_found and together else rooms

    objects: list[tuple[dict[str, float], bool]] = [({kind: 1.0}, False) for kind in stays.values()]
    for s, rooms in stands.items():  # set out with the items: where they are likeliest, until some are found
        out = _set_out(goal, s)
        follows = out and not together and bool(items_together[0])
        objects.append((beside(rooms, items_together[0]) if follows else rooms, out))
    parts = [*objects, items_together] if items else objects

    mass: dict[str, float] = {}
    for rooms, with_found in parts:
        for kind, n in expected(rooms, with_found).items():
            mass[kind] = mass.get(kind, 0.0) + n
    # the sides: each item by its own evidence (a bag kept on a lawn, the money indoors)
    return RoomMass(mass, frozenset().union(*(sides_of(expected(*part)) for part in [*objects, *each_item])))


def delivered_rooms(agenda: Agenda, item: str, placed: dict[str, str]) -> dict[str, float]:
    """Room type -> where the missing ``item`` is: where it is kept (:func:`item_rooms`) and, when the goal puts it
    into or onto a piece of furniture (:func:`furniture_destination`), that furniture's room with the share of
    such items that bddl's other activities set out there (:func:`~more_agent.planners.whereabouts.destination_share`:
    what is loaded into a car waits beside it on the lawn; packing_picnic_food_into_car seed 1 opened a kitchen's
    19 cabinets for the hamburgers that lay on the lawn). The furniture's room is the one it was found in
    (``placed``), else where its kind stands (:func:`~more_agent.planners.room_types.furniture_rooms`)."""
    goal, own = agenda.goal, item_rooms(agenda.goal, [item])
    target = furniture_destination(agenda, item)
    share = destination_share(scope_synset(target), goal.activity) if target is not None else None
    if target is None or share is None:
        return own
    kind = placed.get(target)
    there = {kind: 1.0} if kind else furniture_rooms(goal.categories.get(target, ()))
    if not there or not own:
        return there or own
    return {k: share * there.get(k, 0.0) + (1 - share) * own.get(k, 0.0) for k in {*own, *there}}


def furniture_destination(agenda: Agenda, item: str) -> str | None:
    """The piece of furniture the goal puts ``item`` into or onto, directly or in what it goes into (the
    hamburger goes into a bag, the bag into the car); None when it goes on a floor or nothing standing."""
    goal, seen = agenda.goal, {item}
    while True:
        lit = next(
            (x for x in agenda.literals if not x.negated and x.predicate in RELATIONS and x.args[0] == item), None
        )
        if lit is None or goal.is_floor(lit.args[1]) or lit.args[1] in seen:
            return None
        item = lit.args[1]
        if is_furniture_scope(agenda, item):
            return item
        seen.add(item)


def destination_rooms(belief: Belief, agenda: Agenda) -> dict[str, str]:
    """Scope -> the room type of the region the furniture bound to it was found in, for the goal's furniture."""
    out = {}
    for scope, label in belief.bound.items():
        region = belief.found_in.get(label)
        kind = belief.room_types.get(region) if region is not None else None
        if kind and is_furniture_scope(agenda, scope):
            out[scope] = kind
    return out


def _set_out(goal: TaskGoal, scope: str) -> bool:
    """Whether the task's objects are set out with ``scope``'s: it is no scene fixture (a trash can, a carton;
    not a fridge, a car, a shelf)."""
    return not all(is_scene_fixture(c) for c in goal.categories.get(scope, ()))


def item_rooms(goal: TaskGoal, items: Sequence[str]) -> dict[str, float]:
    """Room type -> where the missing ``items`` (scopes) are kept: the mean of their room priors
    (:func:`~more_agent.planners.whereabouts.room_prior`, the goal's own activity left out) over the items
    that have evidence; {} when none has."""
    return mean_rooms([room_prior(scope_synset(s), goal.activity) for s in items])


def mean_rooms(priors: Sequence[dict[str, float]]) -> dict[str, float]:
    """Room type -> the mean of the room ``priors`` that have evidence; {} when none has."""
    known = [p for p in priors if p]
    kinds = {kind for p in known for kind in p}
    return {kind: sum(p.get(kind, 0.0) for p in known) / len(known) for kind in kinds}


def unseen_floor(sit: Situation, regions: Sequence[str]) -> dict[str, float]:
    """Region id -> the most unseen floor (m^2) in sensor range of one of its frontiers (0 without a map)."""
    occupancy = sit.graph.occupancy
    frontiers = [(rid, f) for rid in regions for f in sit.graph.frontiers(rid)]
    best = dict.fromkeys(regions, 0.0)
    if occupancy is None or not frontiers:
        return best
    points = np.asarray([f for _, f in frontiers], dtype=float)
    gain = visible_unknown_area(occupancy.grid, occupancy.frame, points, range_m=sit.sensor_range_m)
    for (rid, _), g in zip(frontiers, gain):
        best[rid] = max(best[rid], float(g))
    return best


def task_rooms(belief: Belief, agenda: Agenda) -> set[str]:
    """Regions where the objects the goal moves were found (not where the robot put them): a task's
    items are set out together (a store's groceries, a kitchen's food), so its other items are
    likeliest there. Furniture a goal only names as a target (any cabinet the plates may go in)
    tells nothing of where they are."""
    return {rid for rid in _found_regions(belief, agenda) if rid is not None}


def found_rooms(belief: Belief, agenda: Agenda) -> list[str]:
    """The room type of the region each of the task's items was found in (as :func:`task_rooms`), where known."""
    kinds = (belief.room_types.get(rid) for rid in _found_regions(belief, agenda) if rid is not None)
    return [kind for kind in kinds if kind]


def _found_regions(belief: Belief, agenda: Agenda) -> list[str | None]:
    """The region each object the goal moves was found in, one per bound scope."""
    return [belief.found_in[belief.bound[s]] for s in _moved(agenda) if s in belief.bound]


def _moved(agenda: Agenda) -> list[str]:
    """The scopes the goal moves: the first argument of each relation it asks for."""
    return list(dict.fromkeys(lit.args[0] for lit in agenda.literals if lit.predicate != "open"))


def stale(belief: Belief, region: str) -> bool:
    """Whether the region's last explores revealed no object not seen before."""
    return belief.fruitless[region] >= FRUITLESS_EXPLORES


def explore_step(sit: Situation, region: str, note: str) -> Choice:
    """Explore ``region`` towards its frontiers that show the most unseen floor, of those the ones far from
    the robot's path. Unseen floor comes first: a frontier in a pocket behind a tree or a shelf can lie far
    from the path and show little, and bringing_newspaper_in seed 1 spent its garden's explores on such
    pockets, the garden went stale and the newspaper at its far end, beside a frontier facing open unseen
    lawn, was never seen."""
    rich = informative(sit, sit.graph.frontiers(region))
    room = sit.names[region]
    return Choice(Step("explore", (room,), Area(room, region, far_frontiers(rich, sit.path)), note=note))


def informative(sit: Situation, frontiers: Sequence[XY]) -> tuple[XY, ...]:
    """The frontiers from which the most unknown floor lies in sensor range (``INFORMATIVE_SHARE``):
    a frontier at the edge of a large unseen area before one beside a corner nearly seen."""
    occupancy = sit.graph.occupancy
    if occupancy is None or len(frontiers) < 2:
        return tuple(frontiers)
    gain = visible_unknown_area(occupancy.grid, occupancy.frame, np.asarray(frontiers), range_m=sit.sensor_range_m)
    return tuple(f for f, g in zip(frontiers, gain) if g >= INFORMATIVE_SHARE * gain.max())


def far_frontiers(frontiers: Sequence[XY], path: Sequence[XY]) -> tuple[XY, ...]:
    """The frontiers far from everywhere the robot has been (``FAR_FRONTIER_SHARE``): explore() drives
    to the nearest of them, so a garden or a store is crossed instead of covered a few metres at a time."""
    if not frontiers:
        return ()
    gap = _gap_to_path(np.asarray(frontiers, dtype=float), path)
    return tuple(f for f, d in zip(frontiers, gap) if d >= FAR_FRONTIER_SHARE * gap.max())


def _far_corner_gap(obj: ObjectNode, path: Sequence[XY]) -> float:
    """How far the corner of ``obj``'s footprint farthest from the robot's path is from it: a long shelf
    passed at one end still has its other end to show."""
    (x0, y0), (x1, y1) = obj.bbox.min[:2], obj.bbox.max[:2]
    corners = np.array([(x0, y0), (x0, y1), (x1, y0), (x1, y1)], dtype=float)
    return float(_gap_to_path(corners, path).max())


def _gap_to_path(points: np.ndarray, path: Sequence[XY]) -> np.ndarray:
    """Distance from each of ``points`` (n x 2) to the nearest point of the robot's path (every 4th
    point, 0.3 m apart); infinite before the robot has moved."""
    seen = np.asarray(path[::4] or [(math.inf, math.inf)], dtype=float)
    return np.sqrt(((points[:, None, :] - seen[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
