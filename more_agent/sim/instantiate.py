"""Task instantiation: put a BEHAVIOR-1K activity into a world built from a scene.

Steps (all deterministic for a given task, scene and seed):
1. Scopes bound by ``inroom`` literals take existing scene objects: per room type, the first room
   of that type (scene order) where every such scope gets its own piece of furniture of a matching
   category (bipartite matching); ``floor.n.01_k`` takes that room's floor. Wall fixtures the plan
   leaves out (wall nails, hooks, mirrors, ...) are hung first where bddl lists them and a scope
   needs their category (``sim.fixtures``).
2. ``agent.n.01_1`` stands for the robot; substances and ``future`` objects are virtual scopes.
3. Every other scope becomes a new item: category from the synset (the synset's own category when
   it has one, else one drawn with the seed), size from the catalogue, name from the scope
   ('apple.n.01_1' -> 'apple_1').
4. Placement literals run supports first (topological order): ``ontop``/``inside`` rest the item on
   / in its support (on a floor: at a free spot sampled against furniture, walls, doors and other
   floor items; elsewhere at a free slot that no other box reaches into, drawn with the seed as
   OmniGibson samples a pose over the support, ``sim.packing.free_slot``: not inside a TV standing on
   the same table, on the highest level within reach of a tall shelf);
   ``under`` puts it on the floor at the support's footprint centre; ``nextto`` /
   ``touching`` on the floor beside the other object, or on the same support when that object is
   not on a floor. Openable containers that receive items are closed unless an ``open`` literal
   says otherwise; then ``open`` / ``not open`` literals set articulation.
5. The scene's own small objects are added as distractor items (``sim.clutter``).
6. The robot starts at a random reachable pose (``sim.start``), or with ``start="task-room"`` at a
   free spot of the room of its ``ontop agent floor`` literal.
7. Only the instances the description names get their labels now; every other instance is
   labelled when first observed (``TaskInstance.labels``, :mod:`more_agent.sim.labels`).
8. Every supported init literal is evaluated through our bddl backend; a false one raises
   ``InstantiationError`` naming it. Literals that do not apply to rearrangement (cooked,
   covered, filled, ...), ``attached`` (``predicates.NOT_SET_UP``) and literals over virtual scopes
   are kept in ``unsupported_literals``.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

import networkx as nx
import numpy as np
from bddl.condition_evaluation import compile_state

from more_agent.errors import UserError
from more_agent.sim import catalog
from more_agent.sim.ambiguity import SCOPE_WORD
from more_agent.sim.bddl_backend import ScopeObject, WorldBackend
from more_agent.sim.clutter import Clutter, add_distractors, clutter_rng
from more_agent.sim.descriptions import check_description_mode, description_template
from more_agent.sim.fixtures import hang_listed_fixtures
from more_agent.sim.floorspots import free_floor_spot
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.matching import maximum_matching
from more_agent.sim.packing import support_surface
from more_agent.sim.predicates import NOT_SET_UP, PREDICATES, ROBOT_NAME
from more_agent.sim.scene import FREE_SPACE_CLASSES, Scene
from more_agent.sim.start import StartFacts, random_start, start_facts
from more_agent.sim.start_modes import check_start
from more_agent.sim.tasks import (
    TaskDefinition,
    category_phrase,
    check_scene_suits,
    draw_scenes,
    literal_text,
    load_task,
)
from more_agent.sim.world import World, WorldObject, floor_name
from more_agent.vocabulary import scope_synset

_T = TypeVar("_T")

PLACEMENT_PREDICATES = ("ontop", "inside", "under", "nextto", "touching")
"""Init predicates that decide where an item rests, in order of preference."""

ROBOT_CLEARANCE_M = 0.35
"""Radius kept free of furniture around the robot's start pose."""

FLOOR_MARGIN_M = 0.1
"""Gap kept between a floor item and walls, furniture and other floor items."""

GROUND_CATEGORIES = {"floor": "floors", "driveway": "driveway", "lawn": "lawn", "carpet": "carpet"}
"""World ground class -> BEHAVIOR category; scopes of these bind to a room's floor object."""

ParsedLiteral = list


class InstantiationError(UserError):
    """A task cannot be put into a scene; the message names the literal or requirement that failed."""

    def __init__(self, message: str, literal: str | None = None) -> None:
        super().__init__(f"cannot satisfy {literal}: {message}" if literal else message)
        self.literal = literal


@dataclass
class TaskInstance:
    """A task put into a world: what planners, actions and goal checks work on."""

    task: str
    scene: str
    seed: int
    world: World
    description: str
    scope: dict[str, str]
    """Scope name -> world object name ('robot' for the agent; virtual scopes map to themselves)."""
    virtual_scopes: list[str]
    """Scopes the world does not model (substances, future objects)."""
    unsupported_literals: list[str]
    """Init literals (BDDL form, scope names) not applied because rearrangement does not model them."""
    timings: dict[str, float]
    definition: TaskDefinition = field(repr=False)
    start_mode: str = "random"
    """How the robot's start was chosen (``start_modes.START_MODES``)."""
    distractors: list[str] = field(default_factory=list)
    """World names of the scene's own small objects added as items (``sim.clutter``)."""
    start: StartFacts | None = None
    """Start room, task rooms and start-to-task path length at the start."""
    descriptions: str = "named"
    """How the description was written (``descriptions.DESCRIPTION_MODES``)."""
    description_template: str = ""
    """The description with ``$scope`` words where it names instances (``descriptions.description_template``)."""
    class_description: str = ""
    """The description naming instances by class ('the fridge'), for planners whose scene text shows
    classes, not instance labels (MoMa-LLM: :func:`class_description`)."""
    labels: InstanceLabels = field(default_factory=InstanceLabels)
    """What the robot calls the objects: those the description names reserved up front, the rest as observed."""

    def scope_objects(self) -> dict[str, ScopeObject]:
        """The filled bddl scope: every entry a ``ScopeObject``."""
        virtual = set(self.virtual_scopes)
        return {
            s: ScopeObject(s, name, "agent" if name == ROBOT_NAME else "virtual" if s in virtual else "object")
            for s, name in self.scope.items()
        }

    def label(self, scope: str) -> str:
        """Readable name of a scope's object: its label ('apple A') or, before it is observed, its
        category; a floor's room or 'the robot'."""
        return _readable(self.world, self.labels, self.scope[scope])


def instantiate(
    task: str,
    scene: str | None = None,
    seed: int = 0,
    *,
    start: str = "random",
    distractors: bool = True,
    descriptions: str = "named",
) -> TaskInstance:
    """Instantiate ``task`` with ``seed`` in a scene generated with that seed.

    Without ``scene``, the scene is drawn with the seed among the task's suitable ones
    (``tasks.draw_scenes``; the next in the draw is tried when one cannot hold the task); a named
    scene must suit the task (scene .json files are taken as they are). ``start`` is one of
    ``START_MODES``; ``distractors`` adds the scene's own small objects (``sim.clutter``);
    ``descriptions`` is one of ``DESCRIPTION_MODES``.
    """
    t0 = time.perf_counter()
    check_start(start)
    check_description_mode(descriptions)
    definition = load_task(task)
    t_parse = time.perf_counter() - t0
    if scene is None:
        candidates = draw_scenes(task, seed)
        if not candidates:
            raise InstantiationError(f"no BEHAVIOR-1K scene suits task {task!r} (its inroom requirements match none)")
    else:
        candidates = [scene]
        check_scene_suits(task, scene)
    from more_agent.sim.scenes import get_scene

    failures: list[str] = []
    for name in candidates:
        t1 = time.perf_counter()
        scene_obj = get_scene(name, seed)
        t_scene = time.perf_counter() - t1
        try:
            instance = instantiate_in_scene(
                definition, scene_obj, seed, start=start, distractors=distractors, descriptions=descriptions
            )
        except InstantiationError as e:
            if scene is not None:
                raise InstantiationError(f"{e} (scene {name}, seed {seed}); choose another --seed or --scene") from None
            failures.append(f"{name}: {e}")
            continue
        instance.timings.update(parse=t_parse, scene=t_scene, total=time.perf_counter() - t0)
        return instance
    raise InstantiationError(
        f"task {task!r} cannot be placed in any of its {len(candidates)} scenes with seed {seed} "
        f"(first: {failures[0]}); choose another --seed or a --scene"
    )


def instantiate_in_scene(
    definition: TaskDefinition | str,
    scene: Scene,
    seed: int = 0,
    *,
    start: str = "random",
    distractors: bool = True,
    descriptions: str = "named",
) -> TaskInstance:
    """Instantiate a task in a given ``Scene`` object (hand-built scenes included)."""
    if isinstance(definition, str):
        definition = load_task(definition)
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    world = World.from_scene(scene)
    builder = _Builder(definition, world, rng)
    builder.bind_room_objects()
    builder.create_items()
    t_bind = time.perf_counter() - t0
    builder.place_items()
    clutter = add_distractors(world, clutter_rng(scene.name, seed)) if distractors else Clutter()
    t_clutter = time.perf_counter() - t0 - t_bind
    targets = builder.task_objects()
    if start == "task-room":
        builder.place_robot()
    else:
        start_rng = np.random.default_rng([seed, zlib.crc32(definition.name.encode()), 0x57])
        builder.place_robot_at_random(targets, start_rng, by_room=start == "random")
    t_place = time.perf_counter() - t0 - t_bind - t_clutter
    instance = TaskInstance(
        task=definition.name,
        scene=scene.name,
        seed=seed,
        world=world,
        description="",
        scope=builder.scope,
        virtual_scopes=sorted(builder.virtual),
        unsupported_literals=builder.unsupported,
        timings={},
        definition=definition,
        start_mode=start,
        distractors=clutter.items,
        start=start_facts(world, targets),
        descriptions=descriptions,
    )
    _verify_init(instance)
    instance.description = task_description(instance)
    instance.class_description = class_description(instance)
    instance.timings.update(bind=t_bind, place=t_place, clutter=t_clutter, instantiate=time.perf_counter() - t0)
    return instance


def task_description(instance: TaskInstance) -> str:
    """The description of ``descriptions.description_template`` with ``$scope`` words replaced by labels.

    The instances it names get their labels here, before the episode, so that the description and
    the scene text agree; every other instance is labelled when first observed.
    """
    instance.description_template = description_template(
        instance.definition, instance.world, instance.scope, instance.descriptions
    )
    return SCOPE_WORD.sub(lambda m: _scope_phrase(instance, m.group(1)), instance.description_template)


def class_description(instance: TaskInstance) -> str:
    """The description with each scope object named by its class ('the fridge') rather than its label
    ('fridge A'): what a scene text listing classes (MoMa-LLM's) can show. Floors and scopes without a
    world object read as in :func:`task_description`."""

    def phrase(scope: str) -> str:
        obj = instance.world.objects.get(instance.scope.get(scope, ""))
        return f"the {obj.category}" if obj is not None and obj.kind != "floor" else _scope_phrase(instance, scope)

    return SCOPE_WORD.sub(lambda m: phrase(m.group(1)), instance.description_template)


def _scope_phrase(instance: TaskInstance, scope: str) -> str:
    """A scope's label; a scope the paper names but bddl 3.6 lacks reads as 'the <category>'."""
    if scope in instance.scope:
        return _readable(instance.world, instance.labels, instance.scope[scope], reserve=True)
    return f"the {category_phrase(scope_synset(scope))}"


def _listed_or_turned(obj: WorldObject, attempt: Callable[[bool], _T | None]) -> _T | None:
    """``attempt(turned)`` with the item as it is listed, else turned a quarter about the vertical (a box lies
    either way: a baking sheet across a counter's free strip, a pickup along a driveway); the item is left as
    listed when both give None."""
    result = attempt(False)
    if result is None:
        obj.size = obj.size[[1, 0, 2]]
        result = attempt(True)
        if result is None:
            obj.size = obj.size[[1, 0, 2]]
    return result


class _Builder:
    """Scratch state of one instantiation."""

    def __init__(self, definition: TaskDefinition, world: World, rng: np.random.Generator) -> None:
        self.d, self.world, self.rng = definition, world, rng
        self.slots = rng.spawn(1)[0]
        """The slots' own stream (``sim.packing.free_slot``): drawing them leaves every other draw as it was."""
        self.scope: dict[str, str] = {}
        self.virtual: set[str] = set()
        self.unsupported: list[str] = []
        self.items: list[str] = []
        self.agent_floor: str | None = None
        self.areas: dict[str, tuple[float, float, float, float]] = {}
        future = {lit[1] for lit in definition.init if lit[0] == "future"}
        tax = catalog.taxonomy()
        for synset, scopes in definition.objects.items():
            for s in scopes:
                if synset == "agent.n.01":
                    self.scope[s] = ROBOT_NAME
                elif s in future or (tax.is_valid_synset(synset) and tax.has_ability(synset, "substance")):
                    self.scope[s] = s
                    self.virtual.add(s)

    # -- step 1: scene objects --------------------------------------------------------------------
    def bind_room_objects(self) -> None:
        by_type: dict[str, list[str]] = {}
        for lit in self.d.init:
            if lit[0] == "inroom" and lit[1] not in self.scope:
                by_type.setdefault(lit[2], []).append(lit[1])
        for room_type, scopes in by_type.items():
            rooms = [r for r in self.world.scene.rooms if r.type == room_type]
            if not rooms:
                raise InstantiationError(
                    f"scene {self.world.scene.name} has no {room_type}", literal_text(["inroom", scopes[0], room_type])
                )
            ground = [s for s in scopes if _ground_class(scope_synset(s))]
            fixed = [s for s in scopes if s not in ground]
            needed = {c for s in fixed for c in catalog.synset_categories(scope_synset(s))}
            for room in rooms:
                hang_listed_fixtures(self.world, room.id, needed)
            best_room, best = rooms[0].id, self._match_room(rooms[0].id, fixed)
            for room in rooms[1:]:
                if len(best) == len(fixed):
                    break
                match = self._match_room(room.id, fixed)
                if len(match) > len(best):
                    best_room, best = room.id, match
            best |= {s: floor_name(best_room) for s in ground}
            for s in ground:
                self._bind_ground_patch(s, best_room)
            missing = [s for s in scopes if s not in best]
            if missing:
                raise InstantiationError(
                    f"no {room_type} of scene {self.world.scene.name} holds a {scope_synset(missing[0])} "
                    f"for every inroom scope ({', '.join(missing)} unmatched)",
                    literal_text(["inroom", missing[0], room_type]),
                )
            self.scope.update(best)

    def _bind_ground_patch(self, scope: str, room_id: str) -> None:
        """Items put on a driveway / carpet scope go on the room's patch of that ground, if it has one."""
        ground = _ground_class(scope_synset(scope))
        patches = [p.bounds for p in self.world.scene.ground_patches if p.room == room_id and p.ground == ground]
        if patches:
            self.areas[scope] = patches[0]

    def _match_room(self, room_id: str, scopes: list[str]) -> dict[str, str]:
        """Largest one-to-one assignment of scopes to this room's furniture / doors of matching category."""
        door_rooms = {d.id: d.rooms for d in self.world.scene.doors}
        candidates = [
            obj
            for obj in self.world.objects.values()
            if obj.kind in ("furniture", "door") and (obj.room == room_id or room_id in door_rooms.get(obj.name, ()))
        ]
        cats = {s: set(catalog.synset_categories(scope_synset(s))) for s in scopes}
        matching = maximum_matching(scopes, candidates, lambda s, obj: obj.category in cats[s])
        return {s: obj.name for s, obj in matching.items()}

    # -- step 3: new items --------------------------------------------------------------------------
    def create_items(self) -> None:
        sized = set(catalog.sized_categories())
        taken = set(self.world.objects) | {ROBOT_NAME}
        for s in self.d.scopes:
            if s in self.scope:
                continue
            synset = scope_synset(s)
            cats = [c for c in catalog.synset_categories(synset) if c in sized]
            if not cats:
                raise InstantiationError(f"no object category with a known size for {synset} (scope {s})")
            lemma = synset.split(".")[0]
            category = lemma if lemma in cats else str(self.rng.choice(cats))
            name = _item_name(s, taken)
            taken.add(name)
            self.world.add(
                WorldObject(
                    name=name,
                    category=category,
                    kind="item",
                    synset=synset,
                    center=np.zeros(3),
                    size=np.array(catalog.category_size(category), dtype=float),
                    openable=catalog.is_openable(category),
                    cloth=catalog.is_cloth(category),
                )
            )
            self.scope[s] = name
            self.items.append(s)

    # -- step 4: placement ----------------------------------------------------------------------------
    def place_items(self) -> None:
        placement: dict[str, ParsedLiteral] = {}
        states: list[ParsedLiteral] = []
        for lit in self.d.init:
            atom, negated = (lit[1], True) if lit[0] == "not" else (lit, False)
            pred, args = atom[0], atom[1:]
            if pred == "inroom" or (pred == "ontop" and args[0] in self.scope and self.scope[args[0]] == ROBOT_NAME):
                if pred == "ontop":
                    self.agent_floor = self.scope.get(args[1])
                continue
            if pred not in PREDICATES or pred in NOT_SET_UP or any(a in self.virtual for a in args):
                self.unsupported.append(literal_text(lit))
            elif pred == "open":
                states.append(lit)
            elif pred in PLACEMENT_PREDICATES and not negated and args[0] in self.items:
                current = placement.get(args[0])
                if current is None or PLACEMENT_PREDICATES.index(pred) < PLACEMENT_PREDICATES.index(current[0]):
                    placement[args[0]] = atom
        order = nx.DiGraph()
        order.add_nodes_from(self.items)
        for s, atom in placement.items():
            if atom[2] in self.items:
                order.add_edge(atom[2], s)
        try:
            ordered = list(nx.lexicographical_topological_sort(order))
        except nx.NetworkXUnfeasible:
            raise InstantiationError(f"task {self.d.name}: init placements form a cycle") from None
        opened = {lit[1] for lit in states if lit[0] == "open"}
        for s in ordered:
            atom = placement.get(s)
            if atom is None:
                self._on_free_floor(self.scope[s], self._default_floor())
            else:
                self._place(atom, opened)
        for lit in states:
            negated = lit[0] == "not"
            target = self.world.objects[self.scope[(lit[1] if negated else lit)[1]]]
            if not target.openable:
                raise InstantiationError(
                    f"{target.name} ({target.category}) cannot be opened or closed", literal_text(lit)
                )
            self.world.set_open(target.name, not negated)

    def _place(self, atom: ParsedLiteral, opened: set[str]) -> None:
        pred, a, b = atom[0], self.scope[atom[1]], self.scope[atom[2]]
        support = self.world.objects[b]
        if pred in ("ontop", "inside") and support.kind == "floor":
            self._on_free_floor(a, b, area=self.areas.get(atom[2]))
        elif pred in ("ontop", "inside"):
            self._on_support(a, b, pred, atom)
            if pred == "inside" and support.openable and atom[2] not in opened:
                support.is_open = False
        elif pred == "under":
            floor = floor_name(support.room)  # type: ignore[arg-type]  # a support stands in a room
            self.world.place_on_floor_at(a, floor, (float(support.center[0]), float(support.center[1])))
        elif support.parent is None or self.world.objects[support.parent].kind == "floor" or support.kind != "item":
            self._on_free_floor(a, floor_name(support.room), near=support)  # type: ignore[arg-type]  # as above
        else:
            self._on_support(a, support.parent, support.relation or "ontop", atom)

    def _on_support(self, name: str, support: str, relation: str, atom: ParsedLiteral) -> None:
        """Rest ``name`` at a free slot of ``support``, on the items already there when it is full;
        unlike a magic place action, never where another box already is (a full closed container
        fails this scene). An item with no slot as it comes is turned a quarter and tried again when
        its turned footprint lies within the surface (the slot grid follows the item's footprint:
        a baking sheet finds the strip a microwave leaves on a counter only lying across it)."""
        obj = self.world.objects[name]

        def place(turned: bool) -> bool | None:
            if turned:
                lo, hi, _ = support_surface(self.world.objects[support], relation)  # type: ignore[arg-type]
                if not np.all(obj.size[:2] <= hi - lo):
                    return None
            return self.world.place_if_room(name, support, relation, stack=True, rng=self.slots) or None  # type: ignore[arg-type]  # ontop / inside

        if _listed_or_turned(obj, place) is None:
            raise InstantiationError(f"no free spot for {name} {relation} {support}", literal_text(atom))

    def _default_floor(self) -> str:
        return self.agent_floor or floor_name(self.world.scene.rooms[0].id)

    def _on_free_floor(
        self,
        name: str,
        floor: str,
        near: WorldObject | None = None,
        area: tuple[float, float, float, float] | None = None,
    ) -> None:
        obj, room = self.world.objects[name], self.world.objects[floor].room
        xy = _listed_or_turned(obj, lambda _: self._floor_spot(name, room, near, area))  # a pickup along a driveway
        if xy is None:
            where = f"beside {near.name}" if near is not None else f"on the floor of {room}"
            raise InstantiationError(f"no free spot for {name} {where}")
        self.world.place_on_floor_at(name, floor, xy)

    def _floor_spot(
        self,
        name: str,
        room: str | None,
        near: WorldObject | None,
        area: tuple[float, float, float, float] | None,
    ) -> tuple[float, float] | None:
        """A free spot for the item as it lies now: one that keeps every passage open, else any free one."""
        obj = self.world.objects[name]
        half, ground = obj.size[:2] / 2 + FLOOR_MARGIN_M, obj.category in FREE_SPACE_CLASSES
        # when every spot closes a passage, bddl still puts it on this floor, which the base drives over
        for keep in (True, False):
            xy = free_floor_spot(
                self.world,
                room,
                half,
                self.rng,
                near=near,
                exclude=name,
                bounds=area,
                keep_passages=keep,
                ground=ground,
            )
            if xy is not None:
                return xy
        return None

    # -- step 5: robot ------------------------------------------------------------------------------
    def task_objects(self) -> list[str]:
        """World names of the task's objects the robot may go to: items, furniture and doors of the scope
        (floors only when the scope holds nothing else)."""
        names = [n for s, n in self.scope.items() if s not in self.virtual and n != ROBOT_NAME]
        solid = sorted({n for n in names if self.world.objects[n].kind != "floor"})
        return solid or sorted(set(names))

    def place_robot_at_random(self, targets: list[str], rng: np.random.Generator, *, by_room: bool) -> None:
        pose = random_start(self.world, targets, rng, by_room=by_room)
        if pose is None:
            raise InstantiationError(f"no free spot for the robot from which {', '.join(targets[:3])} can be reached")
        self.world.set_robot_pose(*pose)

    def place_robot(self) -> None:
        floor = self._default_floor()
        room = self.world.objects[floor].room
        xy = free_floor_spot(self.world, room, np.full(2, ROBOT_CLEARANCE_M), self.rng, keep_passages=False)
        if xy is None:
            raise InstantiationError(f"no free spot for the robot in {room}")
        self.world.set_robot_pose(xy[0], xy[1], float(self.rng.uniform(-np.pi, np.pi)))


def _ground_class(synset: str) -> str | None:
    """The world ground class a synset stands for ('floor.n.01' -> 'floor', 'driveway.n.01' -> 'driveway'), if any."""
    cats = set(catalog.synset_categories(synset))
    return next((g for g, c in GROUND_CATEGORIES.items() if c in cats), None)


def _item_name(scope: str, taken: set[str]) -> str:
    """'apple.n.01_1' -> 'apple_1'; 'plate.n.04_1' -> 'plate_n04_1' when 'plate_1' is taken."""
    synset, index = scope.rsplit("_", 1)
    lemma, _, sense = synset.split(".")
    for name in (f"{lemma}_{index}", f"{lemma}_n{sense}_{index}"):
        if name not in taken:
            return name
    k = 2
    while f"{lemma}_n{sense}_{index}_{k}" in taken:
        k += 1
    return f"{lemma}_n{sense}_{index}_{k}"


def _readable(world: World, labels: InstanceLabels, name: str, *, reserve: bool = False) -> str:
    """How a description names an object; with ``reserve`` an unlabelled one gets its label now."""
    if name == ROBOT_NAME:
        return "the robot"
    obj = world.objects.get(name)
    if obj is None:  # a virtual scope: its world name is the scope name
        return category_phrase(scope_synset(name))
    if obj.kind == "floor":
        room = world.scene.room(obj.room) if obj.room else None
        return f"the {room.type.replace('_', ' ')} floor" if room else "the floor"
    return labels.reserve(obj) if reserve else labels.display(obj)


def _verify_init(instance: TaskInstance) -> None:
    """Evaluate every applied init literal through the backend; raise on the first false one."""
    unsupported = set(instance.unsupported_literals)
    backend = WorldBackend(instance.world)
    scope = instance.scope_objects()
    for lit in instance.definition.init:
        text = literal_text(lit)
        if lit[0] == "inroom" or text in unsupported:
            continue
        if instance.start_mode != "task-room" and lit[0] == "ontop" and instance.scope.get(lit[1]) == ROBOT_NAME:
            continue  # the random start replaces the task's own start room (paper Sec. IV-A)
        head = compile_state(
            [lit], backend, scope=dict(scope), object_map=instance.definition.objects, generate_ground_options=False
        )[0]
        if not head.evaluate():
            raise InstantiationError(f"it does not hold after placement in {instance.scene}", text)
