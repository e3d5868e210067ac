"""MoMa-LLM's own scene encoding (Honerkamp et al. 2024, arXiv 2403.08605), extended to our subpolicies.

MoMa-LLM puts its scene graph into words differently from MORE (Sec. III-C of its paper): the robot's
room and the objects it stands next to; every room found so far with the objects seen in it, by class
(several of a class are listed once each, never told apart; openables carry an ``opened`` / ``closed``
prefix); which rooms have unexplored space leading out of them, and which hold closed doors, each
with a distance word for how far the nearest such place is. Written here from the paper and the
public code's behaviour, not copied (its licence forbids reuse).

What we changed, as the MORE paper's baseline ("which we extend to our set of subpolicies") needs:

- every room lists its ``floor`` (goals on floors: ``go_to_and_place_ontop(kitchen_0, floor)``);
- the held object is said ("holding apple"), since MoMa-LLM's robot never grasps;
- ``moma-llm-sr`` adds MORE's spatial relations (``apple [inside fridge]``), by class;
- MoMa-LLM splits frontiers into those inside a room and those leading out of it; our regions do not
  tell the two apart, so every room with frontiers is listed as having unexplored space leading out,
  the only kind ``explore`` can use in MoMa-LLM. Distances are straight-line from the robot, where
  MoMa-LLM measures the path on its map.

Task descriptions name instances by class too (``GoalSpec.class_text``: 'the fridge', not 'fridge A',
which this text never shows). Names in answers are the class names as listed, without the state prefix; the
:class:`~more_agent.planners.language.SceneView` behind the text (class names, merged entries)
validates and resolves them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from more_agent.planners.language import ObjectText, SceneView
from more_agent.records import ActionRecord
from more_agent.robot import XY
from more_agent.scene_graph import SceneGraph

DISTANCE_WORDS: tuple[tuple[float, str], ...] = ((3.0, "very close"), (10.0, "near"), (20.0, "far"))
"""Upper bounds in metres of MoMa-LLM's distance words; farther is ``distant``."""

FAR_WORD = "distant"

NEARBY_M = 2.5
"""Objects of the robot's room within this distance are the ones it 'stands next to' (MoMa-LLM's value)."""

HISTORY_LAST_N = 5
"""MoMa-LLM shows the last five actions and every earlier failed one."""

STATE_WORDS = {"open": "opened", "closed": "closed"}
"""Object state as MoMa-LLM writes it, a prefix of the class name."""

_STATE_PREFIX = re.compile(r"^\s*(?:opened|closed|open)\s+", re.I)


def distance_word(metres: float) -> str:
    """MoMa-LLM's word for a distance: very close, near, far or distant."""
    return next((word for bound, word in DISTANCE_WORDS if metres < bound), FAR_WORD)


def object_phrase(entry: ObjectText) -> str:
    """One listed object: ``closed fridge``, ``apple [inside fridge]`` (relations under ``moma-llm-sr``)."""
    state = f"{STATE_WORDS[entry.state]} " if entry.state else ""
    relation = f" [{' '.join(entry.relation)}]" if entry.relation else ""
    return f"{state}{entry.name}{relation}"


def listed_objects(entries: Sequence[ObjectText]) -> list[str]:
    """The objects of a room as MoMa-LLM lists them: each instance once (a merged class entry repeats),
    the held object left out (the robot line says it)."""
    return [object_phrase(e) for e in entries if not e.held for _ in range(max(1, len(e.ids)))]


def without_state(name: str) -> str:
    """An answer's object name without a state prefix a model may copy ('closed fridge' -> 'fridge')."""
    return _STATE_PREFIX.sub("", name, count=1)


@dataclass(frozen=True)
class MomaScene:
    """One step's scene in MoMa-LLM's words (:func:`moma_scene`)."""

    robot_room: str
    nearby: tuple[str, ...]
    rooms: tuple[tuple[str, tuple[str, ...]], ...]
    """(room name, listed objects) in name order."""
    unexplored: tuple[tuple[str, str], ...]
    """(room, distance word) of rooms with unexplored space leading out, nearest first."""
    closed_doors: tuple[tuple[str, str], ...]
    """(room, distance word) of rooms holding closed doors, nearest first."""

    def text(self) -> str:
        """The scene lines of the prompt."""
        lines = [f"You are in the {self.robot_room}, standing next to: [{', '.join(self.nearby)}]."]
        lines.append("Rooms and the objects found in them so far:")
        lines += [f"- {room}: [{', '.join(objects)}]." for room, objects in self.rooms]
        lines.append(f"Rooms with unexplored space leading out of them: [{_with_words(self.unexplored)}].")
        if self.closed_doors:
            lines.append(f"Rooms with closed doors that might open up new space: [{_with_words(self.closed_doors)}].")
        return "\n".join(lines)


def _with_words(rooms: Sequence[tuple[str, str]]) -> str:
    return ", ".join(f"{room} ({word})" for room, word in rooms)


def moma_scene(graph: SceneGraph, view: SceneView) -> MomaScene:
    """MoMa-LLM's encoding of ``graph``; ``view`` is its class-name view (room names, merged entries)."""
    robot = graph.robot.position
    by_region = {r.region_id: r for r in view.rooms}
    unexplored: list[tuple[float, str]] = []
    doors: list[tuple[float, str]] = []
    for rid, room in by_region.items():
        if graph.regions[rid].frontiers:
            unexplored.append((_nearest(robot, graph.regions[rid].frontiers), room.name))
        closed = [o.position[:2] for o in graph.objects_in(rid) if o.category == "door" and o.open is False]
        if closed:
            doors.append((_nearest(robot, closed), room.name))
    here = graph.robot.region_id
    nearby = sorted(
        object_phrase(e)
        for e in (by_region[here].objects if here in by_region else ())
        for oid in e.ids
        if not e.held and math.dist(robot, graph.objects[oid].position[:2]) <= NEARBY_M
    )
    return MomaScene(
        robot_room=view.robot_room,
        nearby=tuple(nearby),
        rooms=tuple((r.name, tuple(listed_objects(r.objects))) for r in view.rooms),
        unexplored=tuple((name, distance_word(d)) for d, name in sorted(unexplored)),
        closed_doors=tuple((name, distance_word(d)) for d, name in sorted(doors)),
    )


def _nearest(xy: XY, points: Sequence[Sequence[float]]) -> float:
    return min(math.dist(xy, (float(p[0]), float(p[1]))) for p in points)


def moma_history(actions: Sequence[ActionRecord], last_n: int = HISTORY_LAST_N) -> str:
    """MoMa-LLM's history line: the last ``last_n`` calls and every earlier failed one, each with its outcome."""
    first_recent = max(0, len(actions) - last_n)
    shown = [
        f"{a.name}({', '.join(a.arguments)}) - {'success' if a.ok else 'failure'}"
        for i, a in enumerate(actions)
        if i >= first_recent or not a.ok
    ]
    if not shown:
        return "You have not acted yet."
    return f"Your {len(shown)} previous actions were: {', '.join(shown)}."
