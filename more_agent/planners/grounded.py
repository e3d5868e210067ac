"""The ``grounded`` planner: an ideal reader of the goal, acting only through what the robot observes.

It stands in for a language model that understands the task perfectly. It knows the task's goal in
BDDL form and its description (:class:`more_agent.goal.TaskGoal`, computed by the runner), and the world only through
the same embodiment, scene graph and subpolicies as MORE: no world state, no object positions it
has not seen, no goal checks. What it reaches is therefore the ceiling that perception, mapping,
the scene graph and the subpolicies put on any language planner (``benchmarks/pipeline_ceiling.py``).

Every step (MPC style) it rebuilds the scene graph and:

1. binds each goal scope to an observed instance: the label the description names, else the
   nearest unbound instance of a category that counts as the scope's synset; bindings stay;
2. evaluates every literal of the goal option on what it believes (observed open state and spatial
   relations, its own placements on floors, objects whose box reaches the ground on their room's
   floor) and calls ``done`` when all hold;
3. otherwise acts for the first literal (oracle order: opening, removals, placements with contents
   before their containers move, closing, the robot's own position) whose objects it knows: open a
   closed container before placing inside, grasp, place (on a floor the description names only once
   a region of that room type is known: until then it searches), put down what the hand holds but
   does not need (on the floor, or on low furniture when the goal wants it off that floor);
4. when a needed object is unseen: opens the closed containers of the robot's room (openables that
   hold things, not a laptop; three in a row at most while there is a room to explore; none when
   only furniture is missing), explores the room most likely to hold the missing furniture
   (BEHAVIOR-1K room inventories), a room where the task's items were found (they are set out
   together) before the others, a room whose explores still reveal new objects before the rest,
   then the one explored least often, the nearest; each explore drives to the frontiers farthest
   from the robot's path, of those to the ones with the most unseen floor in sensor range
   (information gain on the robot's own occupancy map). Before the search leaves the rooms where
   the task's items were found (or when their explores reveal nothing new) it drives to their
   tables, shelves and counters it has not been near, where small items show only from close by,
   and opens their closed containers (neither for missing furniture). A room whose last two
   explores revealed nothing new yields to the other containers and closed doors; the planner
   gives up with ``done`` when nothing is left to try.

An action that fails twice the same way is not repeated: its target is dropped from the bindings
(another instance is taken) or, for a named instance, the planner gives up. An object that cannot be
picked up is dropped at once (a category can be both: a store's cartons are furniture, a task's are
items). Regions are labelled with the room type their furniture fits best
(:mod:`more_agent.planners.room_types`).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from more_agent.goal import Literal, TaskGoal
from more_agent.mapping import visible_unknown_area
from more_agent.planners.base import DONE, EpisodeContext, HighLevelAction, StepTrace, needed
from more_agent.planners.goal_order import ORACLE_PREDICATES, PUT_DOWN_MAX_TOP_M, order_literals
from more_agent.planners.language import room_names
from more_agent.planners.policies import Area, Embodiment, PolicyConfig, run_skill
from more_agent.planners.room_types import category_likelihood, is_furniture, likely_room_type
from more_agent.records import FailureReason, LLMUsage
from more_agent.robot import XY, ActionResult
from more_agent.scene_graph import ObjectNode, SceneGraph
from more_agent.sim.catalog import can_hold_things, is_surface
from more_agent.vocabulary import FLOOR

MAX_FAILURES = 2
"""An action is not tried again after failing this many times the same way."""

OPENS_BEFORE_EXPLORING = 3
"""Containers opened to look inside, one after the other, before the search explores again."""

FRUITLESS_EXPLORES = 2
"""A room whose last explores, this many in a row, revealed no new object yields to containers, doors, other rooms."""

FAR_FRONTIER_SHARE = 0.5
"""Explore goes to the frontiers at least this share as far from the robot's path as the farthest one."""

INFORMATIVE_SHARE = 0.75
"""... and of those, to the ones showing at least this share of the most unknown floor in sensor range."""

LOOK_AT_M = 2.0
"""Furniture of the task's rooms with a corner farther than this from everywhere the robot has been is
driven to when an item is missing."""

MAX_REACH_FAILURES = 3
"""An object is given up after this many failed approaches (the robot explores in between)."""

GROUND_M = 0.05
"""An object whose observed box reaches this low, resting on no observed object, stands on the floor."""

Relation = tuple[str, str]
"""(predicate 'inside' / 'ontop', label of the container / support, or 'floor <room>')."""


@dataclass(frozen=True)
class _Step:
    """A decided action (its typed target included), and whether it opens a container to look inside
    (the search counts those in a row, ``OPENS_BEFORE_EXPLORING``)."""

    action: HighLevelAction
    looking: bool = False


class GroundedPlanner:
    """Goal-aware planner on the scene graph (module docstring); no LLM, deterministic."""

    name = "grounded"
    llm: str | None = None
    reads_goal = True
    """The runner hands it the goal's literals (``GoalSpec.goal``)."""

    def __init__(self, llm: str | None = None, *, config: PolicyConfig | None = None) -> None:
        del llm  # plans without a language model
        self.config = config or PolicyConfig()

    # -- Planner protocol ---------------------------------------------------------------------
    def reset(self, context: EpisodeContext) -> None:
        """Read the goal, start the robot with a full turn in place (paper S.3)."""
        if context.goal.goal is None:
            raise ValueError("the grounded planner reads the goal: its GoalSpec must carry the literals")
        self.goal: TaskGoal = context.goal.goal
        self.body = Embodiment(context.robot, config=self.config)
        option = self.goal.options[0]
        self.skipped = [lit for lit in option if lit.predicate not in ORACLE_PREDICATES]
        """Literals no subpolicy can achieve (named when the planner calls done)."""
        self.literals: list[Literal] = order_literals([lit for lit in option if lit not in self.skipped])
        self.bound: dict[str, str] = {}
        self.seen: dict[str, ObjectNode] = {}
        """Label -> the object as last observed (objects of rooms now out of reach included)."""
        self.found_in: dict[str, str | None] = {}
        """Label -> the region the object was first observed in."""
        self.relation: dict[str, Relation | None] = {}
        """Label -> where it rests as last observed or placed."""
        self.looked_into: set[str] = set()
        self.looked_at: set[str] = set()
        """Furniture driven to in search of a missing item (``_furniture_to_look_at``)."""
        self.fruitless_looks = 0
        """Such drives in a row that revealed no new object (the search stops them at ``FRUITLESS_EXPLORES``)."""
        self.dropped: set[str] = set()
        self.out_of_reach: dict[str, int] = {}
        """Label -> trajectory length when an approach failed: skipped until the robot has moved since."""
        self.failures: Counter[tuple[str, tuple[str, ...], str]] = Counter()
        self.opened_in_a_row = 0
        self.explored: Counter[str] = Counter()
        """Region id -> explore() calls so far."""
        self.fruitless: Counter[str] = Counter()
        """Region id -> explore() calls in a row that revealed no new object (``FRUITLESS_EXPLORES``)."""
        self.room_types: dict[str, str] = {}
        self.graph: SceneGraph | None = None
        self.names: dict[str, str] = {}
        self.body.start()

    def observe(self) -> None:
        """Build the scene graph; remember what is seen, where it rests and its open state; type rooms."""
        body = self.body
        graph = body.step_graph(lambda g: _room_types(g, body.room_input))
        self.room_types = {rid: r.room_label for rid, r in graph.regions.items() if r.room_label}
        rel = {r.subject: (r.predicate, graph.objects[r.object].label) for r in graph.relations}
        for obj in graph.objects.values():
            self.seen[obj.label] = obj
            self.found_in.setdefault(obj.label, obj.region_id)
            if obj.open:
                self.looked_into.add(obj.label)
            if obj.held:
                self.relation[obj.label] = None
            elif obj.label in rel or not _on_floor(self.relation.get(obj.label)):
                self.relation[obj.label] = rel.get(obj.label) or self._on_ground(obj)
        self.graph, self.names = graph, room_names(graph)

    def decide(self) -> HighLevelAction:
        """``done`` when every goal literal holds as far as the robot knows, else the next action."""
        step = self._decide()
        self.opened_in_a_row = self.opened_in_a_row + 1 if step.looking else 0
        return step.action

    def execute(self, action: HighLevelAction) -> ActionResult:
        """Run the skill on the action's target, and learn from its outcome."""
        return self._run(action)

    def step_trace(self) -> StepTrace:
        """The scene graph the step planned on."""
        return StepTrace(graph=self.graph)

    def llm_usage(self) -> LLMUsage:
        """No LLM."""
        return LLMUsage()

    # -- beliefs ------------------------------------------------------------------------------
    def _label(self, scope: str) -> str | None:
        """The observed instance a scope is bound to, binding it now if possible (module docstring)."""
        if scope in self.bound:
            return self.bound[scope]
        named = self.goal.named.get(scope)
        if named is not None:
            if named in self.seen:
                self.bound[scope] = named
            return self.bound.get(scope)
        taken = set(self.bound.values()) | set(self.goal.named.values()) | self.dropped
        cats = self.goal.categories.get(scope, frozenset())
        candidates = [o for o in self.seen.values() if o.category in cats and o.label not in taken]
        if not candidates:
            return None
        xy = self.body.xy
        best = min(candidates, key=lambda o: (math.dist(o.position[:2], xy), o.label))
        self.bound[scope] = best.label
        return best.label

    def _on_ground(self, obj: ObjectNode) -> Relation | None:
        """The floor of its room when the object's box reaches the ground (``GROUND_M``): the scene graph
        relates objects to objects only, and without this an item lying on a lawn would be believed
        off it."""
        return None if obj.bbox.min[2] > GROUND_M else self._on_floor_of(obj.region_id)

    def _on_floor_of(self, region: str | None) -> Relation:
        """The relation of an object resting on the floor of ``region``, named by its room type."""
        return ("ontop", f"{FLOOR} {self.room_types.get(region or '', '')}")

    def _floor_region(self, scope: str) -> str | None:
        """A reachable region whose room type is the floor's (any region when the description names none)."""
        graph = self._graph()
        want = self.goal.floor_rooms.get(scope)
        if want is None:
            return graph.robot.region_id
        matches = sorted(rid for rid, kind in self.room_types.items() if kind == want)
        return matches[0] if matches else None

    def _holds(self, lit: Literal) -> bool | None:
        """Whether ``lit`` holds as far as the robot knows; None while one of its objects is unseen."""
        if lit.predicate == "open":
            label = self._label(lit.args[0])
            if label is None:
                return None
            return bool(self.seen[label].open) != lit.negated
        subject, target = lit.args
        if subject == self.goal.robot:
            region = self._floor_region(target)
            return None if region is None else (self._graph().robot.region_id == region) != lit.negated
        a = self._label(subject)
        if a is None:
            return None
        rel = self.relation.get(a)
        if self.goal.is_floor(target):
            want = self.goal.floor_rooms.get(target)
            on = _on_floor(rel) and (want is None or rel[1] == f"{FLOOR} {want}")  # type: ignore[index]
            return on != lit.negated
        b = self._label(target)
        if b is None:
            return None
        return (rel == (lit.predicate, b)) != lit.negated

    # -- deciding -----------------------------------------------------------------------------
    def _decide(self) -> _Step:
        status = [(lit, self._holds(lit)) for lit in self.literals]
        lost = sorted(label for scope, label in self.bound.items() if label in self.dropped)
        if lost:
            why = f"cannot act on {', '.join(lost)}, which the description names"
            return _Step(HighLevelAction(DONE, note=why, gave_up=f"grounded planner gave up: {why}"))
        pending = [(lit, h) for lit, h in status if h is not True]
        if not pending:
            why = "; ".join(lit.text for lit in self.skipped)
            return _Step(
                HighLevelAction(
                    DONE,
                    note="every goal literal holds in the scene graph",
                    gave_up=f"goal literals no subpolicy achieves: {why}" if why else "",
                )
            )
        held = self._graph().held_object
        if held is not None:
            step = self._place_held(held.label, [lit for lit, h in pending if h is False])
            if step is not None:
                return step
        only_closing = all(_closes(lit) for lit, _ in pending)
        for lit, h in pending:
            if _closes(lit) and not only_closing:
                continue  # close last: what is inside may still be needed
            if h is False:
                step = self._act_for(lit, held.label if held is not None else None)
                if step is not None:
                    return step
        # Nothing to act on now: find what is unseen, else what is out of reach.
        missing = next((lit for lit, h in pending if h is None), pending[0][0])
        return self._search(missing, held.label if held is not None else None)

    def _place_held(self, held: str, unmet: list[Literal]) -> _Step | None:
        """Place the held item where an unmet literal wants it, when that target is ready."""
        for lit in unmet:
            if lit.predicate == "open" or lit.negated or self.bound.get(lit.args[0]) != held:
                continue
            target = lit.args[1]
            if self.goal.is_floor(target):
                region = self._floor_region(target)
                if region is not None:
                    return self._floor_step(region, f"for {lit.text}")
                continue
            b = self.bound[target]
            if b in self._reachable() and not self._must_open(b, lit.predicate):
                return self._object_step(f"go_to_and_place_{lit.predicate}", b, f"for {lit.text}")
        return None

    def _act_for(self, lit: Literal, held: str | None) -> _Step | None:
        """The next action towards an unmet literal whose objects are all known, or None if it cannot act now."""
        objects = self._reachable()
        note = f"for {lit.text}"
        if lit.predicate == "open":
            label = self.bound[lit.args[0]]
            if label not in objects:
                return None
            if held is not None:
                return self._put_down(held)
            return self._object_step("go_to_and_close" if lit.negated else "go_to_and_open", label, note)
        subject, target = lit.args
        if subject == self.goal.robot:
            region = self._floor_region(target)
            goal_obj = next((o for o in self._graph().objects_in(region)), None) if region else None
            return self._object_step("navigate", goal_obj.label, note) if goal_obj is not None else None
        a = self.bound[subject]
        if a not in objects:
            return None
        if not lit.negated and self.goal.is_floor(target) and self._floor_region(target) is None:
            return None  # no room of the floor's type found yet: search for it first
        if (
            lit.negated
            and self.goal.is_floor(target)
            and (self._placed_elsewhere(subject) or self._support_for(a) is None)
        ):
            return None  # the placement the goal asks for meets it; putting it down again cannot
        if not lit.negated and not self.goal.is_floor(target):
            b = self.bound[target]
            if b not in objects:
                return None
            if self._must_open(b, lit.predicate):
                return self._put_down(held) if held is not None else self._object_step("go_to_and_open", b, note)
        if held is not None and held != a:
            return self._put_down(held)
        if held == a:  # negated literal: take it away from where it must not be
            return self._put_down(held)
        hider = self._closed_container_of(a)
        if hider is not None:
            return self._object_step("go_to_and_open", hider, note) if hider in objects else None
        return self._object_step("go_to_and_grasp", a, note)

    def _closed_container_of(self, label: str) -> str | None:
        """The closed container ``label`` was last seen (or put) inside, if any."""
        rel = self.relation.get(label)
        if rel is None or rel[0] != "inside" or rel[1] not in self.seen:
            return None
        return rel[1] if self.seen[rel[1]].open is False else None

    def _reachable(self) -> set[str]:
        """Labels of objects in the current graph, less those whose approach failed since the robot last moved."""
        moved = len(self.body.trajectory)
        return {o for o in self._graph().objects if self.out_of_reach.get(o, -1) != moved}

    def _must_open(self, label: str, predicate: str) -> bool:
        obj = self.seen[label]
        return predicate == "inside" and obj.open is False

    def _search(self, lit: Literal, held: str | None) -> _Step:
        """Look for an unseen object of ``lit``: containers here, the likeliest unexplored room, other
        containers, closed doors; give up when none is left."""
        graph = self._graph()
        missing = [s for s in lit.args if s != self.goal.robot and not self.goal.is_floor(s) and self._label(s) is None]
        note = f"looking for {', '.join(self.goal.named.get(s, s) for s in missing) or 'the room of ' + lit.text}"
        here = graph.robot.region_id
        items = not missing or any(not self._is_furniture_scope(s) for s in missing)
        closed = (
            sorted(
                (
                    o
                    for o in graph.objects.values()
                    if o.open is False
                    and can_hold_things(o.category)
                    and o.label not in self.looked_into
                    and o.label not in self.dropped
                ),
                key=lambda o: (o.region_id != here, math.dist(o.position[:2], self.body.xy), o.label),
            )
            if items
            else []
        )
        task_rooms = self._task_rooms()
        region = self._room_to_explore(missing, task_rooms)
        if closed and closed[0].region_id == here and (self.opened_in_a_row < OPENS_BEFORE_EXPLORING or region is None):
            return self._open_to_look(closed[0].label, held, note)
        if items and (region is None or self._stale(region) or region not in task_rooms):
            furniture = self._furniture_to_look_at(task_rooms)
            if furniture is not None:
                return self._object_step("navigate", furniture, note)
            in_task_rooms = [o for o in closed if o.region_id in task_rooms]
            if in_task_rooms:
                return self._open_to_look(in_task_rooms[0].label, held, note)
        if region is not None and not self._stale(region):
            return self._explore_step(region, note)
        if closed:
            return self._open_to_look(closed[0].label, held, note)
        doors = sorted(
            (
                o
                for o in graph.objects.values()
                if o.category == "door" and o.open is False and o.label not in self.dropped
            ),
            key=lambda o: math.dist(o.position[:2], self.body.xy),
        )
        if doors:
            return self._open_to_look(doors[0].label, held, note)
        if region is not None:
            return self._explore_step(region, note)
        why = f"{note}: nothing left to explore or open"
        return _Step(HighLevelAction(DONE, note=why, gave_up=f"grounded planner gave up {why}"))

    def _is_furniture_scope(self, scope: str) -> bool:
        """Whether ``scope`` is furniture: the goal does not move it and every category that counts as it
        is furniture. A missing table is in no cabinet and shows from afar, so the search neither opens
        containers nor drives along shelves for it."""
        cats = self.goal.categories.get(scope, frozenset())
        return scope not in self.goal.moved and bool(cats) and all(is_furniture(c) for c in cats)

    def _furniture_to_look_at(self, rooms: set[str]) -> str | None:
        """The nearest furniture things are put on (tables, shelves, counters: ``sim.catalog.is_surface``)
        of the task's ``rooms`` the robot has not been near (``LOOK_AT_M``): explore() clears a store's
        floor, but groceries on a far shelf show only from close by. None once the last drives revealed nothing."""
        if self.fruitless_looks >= FRUITLESS_EXPLORES:
            return None
        path = self.body.trajectory
        candidates = [
            o
            for o in self._graph().objects.values()
            if o.region_id in rooms
            and o.open is None
            and is_surface(o.category)
            and o.label not in self.looked_at
            and o.label not in self.dropped
            and _far_corner_gap(o, path) > LOOK_AT_M
        ]
        xy = self.body.xy
        return min(candidates, key=lambda o: (math.dist(o.position[:2], xy), o.label)).label if candidates else None

    def _open_to_look(self, label: str, held: str | None, note: str) -> _Step:
        if held is not None:
            return self._put_down(held)
        return _Step(self._object_step("go_to_and_open", label, note).action, looking=True)

    def _room_to_explore(self, missing: list[str], task_rooms: set[str]) -> str | None:
        """The region with unexplored areas to explore next: rooms whose last explores revealed nothing
        new last; then the room most likely to hold the missing furniture; then the rooms of the task's
        items found so far (``task_rooms``, from ``_task_rooms``); then a room whose explores still reveal new objects before
        one not explored yet (a garden or a store is searched through, not left after a few metres);
        then the least explored, the nearest."""
        graph = self._graph()
        cats = [c for s in missing for c in self.goal.categories.get(s, ()) if is_furniture(c)]

        def score(rid: str) -> tuple[bool, float, bool, bool, int, float, str]:
            kind = self.room_types.get(rid)
            like = max((category_likelihood(c, kind) for c in cats), default=0.0) if kind else 0.0
            productive = self.explored[rid] > 0 and self.fruitless[rid] == 0
            return (
                self._stale(rid),
                -like,
                rid not in task_rooms,
                not productive,
                self.explored[rid],
                math.dist(graph.regions[rid].centroid, self.body.xy),
                rid,
            )

        open_regions = [rid for rid, r in graph.regions.items() if r.frontiers]
        return min(open_regions, key=score) if open_regions else None

    def _task_rooms(self) -> set[str]:
        """Regions where the objects the goal moves were found (not where the robot put them): a task's
        items are set out together (a store's groceries, a kitchen's food), so its other items are
        likeliest there. Furniture a goal only names as a target (any cabinet the plates may go in)
        tells nothing of where they are."""
        moved = {lit.args[0] for lit in self.literals if lit.predicate != "open"}
        return {self.found_in[self.bound[s]] for s in moved if s in self.bound} - {None}

    def _stale(self, region: str) -> bool:
        """Whether the region's last explores revealed no object not seen before."""
        return self.fruitless[region] >= FRUITLESS_EXPLORES

    def _explore_step(self, region: str, note: str) -> _Step:
        far = far_frontiers(self._graph().frontiers(region), self.body.trajectory)
        room = self.names[region]
        return _Step(HighLevelAction("explore", (room,), Area(room, region, self._informative(far)), note=note))

    def _informative(self, frontiers: tuple[XY, ...]) -> tuple[XY, ...]:
        """The frontiers from which the most unknown floor lies in sensor range (``INFORMATIVE_SHARE``):
        a frontier at the edge of a large unseen area before one beside a corner nearly seen."""
        occupancy = self._graph().occupancy
        if occupancy is None or len(frontiers) < 2:
            return frontiers
        gain = visible_unknown_area(
            occupancy.grid, occupancy.frame, np.asarray(frontiers), range_m=self.body.builder.config.max_range_m
        )
        return tuple(f for f, g in zip(frontiers, gain) if g >= INFORMATIVE_SHARE * gain.max())

    def _put_down(self, held: str) -> _Step:
        """Free the hand: on the floor where the robot stands, unless the goal wants the item off that
        floor; then on top of the nearest low furniture seen (the oracle's choice), if there is one."""
        here = self._graph().robot.region_id
        note = f"free the hand of {held}"
        support = self._support_for(held) if self._off_floor(held, here) else None
        if support is not None:
            return self._object_step("go_to_and_place_ontop", support, note)
        room = self._room(here)
        return _Step(HighLevelAction("go_to_and_place_ontop", (room, FLOOR), Area(room), note=note))

    def _off_floor(self, held: str, region: str | None) -> bool:
        """Whether a goal literal wants ``held`` off the floor of ``region`` (``not ontop`` a floor scope
        that names no room or names this room's type)."""
        kind = self.room_types.get(region or "")
        return any(
            lit.negated
            and lit.predicate == "ontop"
            and self.goal.is_floor(lit.args[1])
            and self.bound.get(lit.args[0]) == held
            and self.goal.floor_rooms[lit.args[1]] in (None, kind)
            for lit in self.literals
        )

    def _placed_elsewhere(self, scope: str) -> bool:
        """Whether a goal literal places ``scope`` somewhere (which takes it off any floor it must leave)."""
        return any(not lit.negated and lit.predicate != "open" and lit.args[0] == scope for lit in self.literals)

    def _support_for(self, held: str) -> str | None:
        """The nearest reachable observed furniture to put ``held`` on top of: low enough to reach
        (``PUT_DOWN_MAX_TOP_M``), not closed, not given up on; in the robot's room first."""
        here = self._graph().robot.region_id
        spots = [
            o
            for label in self._reachable()
            if label not in self.dropped
            and label != held
            and is_furniture((o := self.seen[label]).category)
            and o.category != "door"
            and o.bbox.max[2] <= PUT_DOWN_MAX_TOP_M
            and o.open is not False
        ]
        if not spots:
            return None
        return min(spots, key=lambda o: (o.region_id != here, math.dist(o.position[:2], self.body.xy), o.label)).label

    def _floor_step(self, region: str, note: str) -> _Step:
        room = self._room(region)
        return _Step(HighLevelAction("go_to_and_place_ontop", (room, FLOOR), Area(room, region), note=note))

    def _object_step(self, skill: str, label: str, note: str) -> _Step:
        obj = self._graph().objects[label]
        return _Step(HighLevelAction(skill, (self._room(obj.region_id), label), obj, note=note))

    def _room(self, region_id: str | None) -> str:
        return self.names.get(region_id or "", "unknown")

    # -- acting -------------------------------------------------------------------------------
    def _run(self, action: HighLevelAction) -> ActionResult:
        body, graph, target = self.body, self._graph(), action.target
        if action.name == DONE or target is None:
            return run_skill(body, graph, DONE, None)
        held = graph.held_object
        known = len(body.observed)
        result = run_skill(body, graph, action.name, target)
        news = len(body.observed) > known
        if isinstance(target, Area):
            if action.name == "explore":
                assert target.region_id is not None
                self.explored[target.region_id] += 1
                self.fruitless[target.region_id] = 0 if news else self.fruitless[target.region_id] + 1
            elif result.ok and held is not None:  # put on a floor
                self.relation[held.label] = self._on_floor_of(target.region_id or graph.robot.region_id)
        elif isinstance(target, ObjectNode):
            if result.ok and action.name == "go_to_and_open":
                self.looked_into.add(target.label)
            if action.name == "navigate":
                self.looked_at.add(target.label)
                if news:  # its room shows more: explore it again
                    self.fruitless[target.region_id or ""] = 0
        self.fruitless_looks = 0 if news else self.fruitless_looks + (action.name == "navigate")
        if not result.ok and isinstance(target, ObjectNode):
            self._failed(action, target.label, result)
        return result

    def _failed(self, action: HighLevelAction, label: str, result: ActionResult) -> None:
        """Count a failure on the object ``label``; an action failing twice the same way drops it from the bindings."""
        if result.reason is FailureReason.NOT_REACHABLE:
            self.out_of_reach[label] = len(self.body.trajectory)
            key, limit = (action.name, action.arguments, "not reachable"), MAX_REACH_FAILURES
        else:  # furniture cannot be picked up however often the robot tries
            limit = 1 if result.reason is FailureReason.NOT_GRASPABLE else MAX_FAILURES
            key = (action.name, action.arguments, result.feedback)
        self.failures[key] += 1
        if self.failures[key] < limit:
            return
        self.dropped.add(label)
        for scope, bound in list(self.bound.items()):
            if bound == label and scope not in self.goal.named:
                del self.bound[scope]

    def _graph(self) -> SceneGraph:
        return needed(self.graph, "observe()")


def _room_types(graph: SceneGraph, read: Callable[[Iterable[ObjectNode]], list[str]]) -> dict[str, str]:
    """Region id -> the room type its furniture fits best, for the regions without a label; ``read`` gives
    the categories the classifier reads for a region's objects (``Embodiment.room_input``)."""
    labels = {}
    for rid, region in graph.regions.items():
        if region.room_label is None:
            kind = likely_room_type(read(graph.objects_in(rid)))
            if kind is not None:
                labels[rid] = kind
    return labels


def _closes(lit: Literal) -> bool:
    return lit.predicate == "open" and lit.negated


def _on_floor(rel: Relation | None) -> bool:
    return rel is not None and rel[1].startswith(f"{FLOOR} ")


def _far_corner_gap(obj: ObjectNode, path: Sequence[XY]) -> float:
    """How far the corner of ``obj``'s footprint farthest from the robot's path is from it: a long shelf
    passed at one end still has its other end to show."""
    (x0, y0), (x1, y1) = obj.bbox.min[:2], obj.bbox.max[:2]
    corners = np.array([(x0, y0), (x0, y1), (x1, y0), (x1, y1)], dtype=float)
    return float(_gap_to_path(corners, path).max())


def far_frontiers(frontiers: Sequence[XY], path: Sequence[XY]) -> tuple[XY, ...]:
    """The frontiers far from everywhere the robot has been (``FAR_FRONTIER_SHARE``): explore() drives
    to the nearest of them, so a garden or a store is crossed instead of covered a few metres at a time."""
    if not frontiers:
        return ()
    gap = _gap_to_path(np.asarray(frontiers, dtype=float), path)
    return tuple(f for f, d in zip(frontiers, gap) if d >= FAR_FRONTIER_SHARE * gap.max())


def _gap_to_path(points: np.ndarray, path: Sequence[XY]) -> np.ndarray:
    """Distance from each of ``points`` (n x 2) to the nearest point of the robot's path (every 4th
    point, 0.3 m apart); infinite before the robot has moved."""
    seen = np.asarray(path[::4] or [(math.inf, math.inf)], dtype=float)
    return np.sqrt(((points[:, None, :] - seen[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
