"""Scene graph -> structured language: the scene text the LLM planners read, and back.

A :class:`SceneView` is the language-side picture of one :class:`~more_agent.scene_graph.SceneGraph`:
rooms (regions named by their LLM room label, ``kitchen_0``), each with its objects (alphabetical
instance ids such as ``fridge A``, or bare classes for MoMa-LLM), their attributes (open / closed,
held by the robot), optional spatial relations (``inside fridge A``, ``on top of table B``), whether
the room still has unexplored areas, and the robot's room and held object. The same view renders the text, lists the
valid names for answer validation, applies the LLM filter (paper Sec. III-B, ``xi -> xi_task``) and
resolves the names in an answer back to scene-graph object ids.

Text format, one line per room (attributes in brackets, as the prompts announce); each room lists
its ``floor`` first, so that goals on floors can be expressed (``go_to_and_place_ontop(kitchen_0, floor)``),
and the object in the robot's hand in the robot's room::

    kitchen_0 (unexplored areas): floor, apple A [inside fridge A], book A [held by the robot], fridge A [closed], table A

What the robot did is visible in the text itself, as the paper's history (the last five actions and
the failed ones) needs: what it holds, where each item it put down rests (with spatial relations)
and whether each openable is open. Relations are those of the scene graph: as perceived (where the
world put things), not guessed from boxes, for the simulator's instances.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, replace

from pydantic import BaseModel, ConfigDict, Field

from more_agent.llm.answers import FilterResult
from more_agent.scene_graph.model import ObjectNode, SceneGraph
from more_agent.vocabulary import FLOOR

UNLABELED_ROOM = "unknown_room"
"""Room name stem of regions the room classifier has not labelled yet."""

UNKNOWN_PLACE = "unknown"
"""Robot room shown when the robot is not in any region of the graph."""

HELD = "held by the robot"
"""Attribute of the held object, listed in the robot's room."""


class LanguageOptions(BaseModel):
    """How the scene graph is put into words; the planners differ only here and in filtering."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    instance_ids: bool = Field(
        default=True, description="Name objects by alphabetical instance id ('fridge A'); False: by class ('fridge')."
    )
    spatial_relations: bool = Field(
        default=True, description="Add 'inside X' / 'on top of X' relations among observed objects."
    )
    floors: bool = Field(
        default=True, description="List each room's floor ('floor') so goals on floors can be expressed."
    )


@dataclass(frozen=True)
class ObjectText:
    """One object as the LLM sees it; ``ids`` are the scene-graph object ids behind the name."""

    name: str
    ids: tuple[str, ...]
    state: str | None = None
    """'open', 'closed', or None when not openable."""
    relation: tuple[str, str] | None = None
    """('inside' or 'on top of', name of the container / support), when relations are shown."""
    held: bool = False
    """The robot holds it (it is listed in the robot's room)."""

    def text(self) -> str:
        """E.g. ``apple A [inside fridge A]``, or ``cabinet (x2) [closed]`` for merged class entries."""
        count = f" (x{len(self.ids)})" if len(self.ids) > 1 else ""
        attrs = ([self.state] if self.state else []) + ([HELD] if self.held else [])
        attrs += [" ".join(self.relation)] if self.relation else []
        bracket = f" [{', '.join(attrs)}]" if attrs else ""
        return f"{self.name}{count}{bracket}"


@dataclass(frozen=True)
class RoomText:
    """One room: its name, region id, objects in text order, and whether it has unexplored areas."""

    name: str
    region_id: str
    objects: tuple[ObjectText, ...]
    unexplored: bool

    def text(self) -> str:
        """The room's line in the scene description."""
        head = f"{self.name} (unexplored areas)" if self.unexplored else self.name
        body = ", ".join(o.text() for o in self.objects) or "no objects seen"
        return f"{head}: {body}"


def room_names(graph: SceneGraph) -> dict[str, str]:
    """Region id -> unique room name: ``<room label>_<k>``, k counting regions of a label in id order."""
    counts: dict[str, int] = {}
    names: dict[str, str] = {}
    for rid in sorted(graph.regions, key=_region_order):
        stem = (graph.regions[rid].room_label or UNLABELED_ROOM).strip().lower().replace(" ", "_")
        names[rid] = f"{stem}_{counts.get(stem, 0)}"
        counts[stem] = counts.get(stem, 0) + 1
    return names


def _region_order(region_id: str) -> tuple[int, str]:
    """Sort 'region_2' before 'region_10'."""
    stem, _, k = region_id.rpartition("_")
    return (int(k), stem) if k.isdigit() else (-1, region_id)


@dataclass(frozen=True)
class SceneView:
    """The scene as the planners put it into words (see module docstring)."""

    rooms: tuple[RoomText, ...]
    robot_room: str
    held: str | None
    """Name of the held object as shown to the LLM, or None."""
    held_id: str | None
    """Scene-graph id of the held object, or None."""

    def text(self) -> str:
        """The scene description: one line per room."""
        return "\n".join(r.text() for r in self.rooms) or "nothing observed yet"

    def names(self) -> dict[str, list[str]]:
        """Room name -> object names (distinct, text order): what answers may name, for the parsers."""
        return {r.name: list(dict.fromkeys(o.name for o in r.objects)) for r in self.rooms}

    def object_names(self) -> list[str]:
        """Every object name an answer may use: those in rooms plus the held object."""
        names = [o for objs in self.names().values() for o in objs]
        return list(dict.fromkeys(names + ([self.held] if self.held else [])))

    def room(self, name: str) -> RoomText:
        """The room with this name (KeyError if none)."""
        for r in self.rooms:
            if r.name == name:
                return r
        raise KeyError(name)

    def resolve(self, room: str | None, name: str) -> tuple[str, ...]:
        """Scene-graph ids an object name may mean: first in ``room``, else anywhere; the held object too."""
        in_room = [i for r in self.rooms if r.name == room for o in r.objects if o.name == name for i in o.ids]
        if in_room:
            return tuple(in_room)
        anywhere = [i for r in self.rooms for o in r.objects if o.name == name for i in o.ids]
        if not anywhere and name == self.held and self.held_id is not None:
            return (self.held_id,)
        return tuple(dict.fromkeys(anywhere))

    def filtered(self, kept: FilterResult, *, always: Collection[str] = ()) -> SceneView:
        """The task subgraph: the rooms the filter kept (plus ``always``, e.g. the robot's room), each
        with its kept objects, the held object and the containers / supports their relations name."""
        rooms = []
        for r in self.rooms:
            if r.name not in kept.rooms and r.name not in always:
                continue
            keep = set(kept.rooms.get(r.name, ())) | {FLOOR} | {o.name for o in r.objects if o.held}
            keep |= {o.relation[1] for o in r.objects if o.name in keep and o.relation is not None}
            rooms.append(replace(r, objects=tuple(o for o in r.objects if o.name in keep)))
        return replace(self, rooms=tuple(rooms))


def scene_view(graph: SceneGraph, options: LanguageOptions, names: Mapping[str, str] | None = None) -> SceneView:
    """The language view of ``graph`` under ``options``; ``names`` maps region ids to room names
    (default :func:`room_names`). The held object is listed in the robot's room (nowhere when the
    robot stands in no region; the robot line of the prompts names it anyway)."""
    names = dict(names) if names is not None else room_names(graph)
    shown = {oid: _shown_name(obj, options) for oid, obj in graph.objects.items()}
    relation_of: dict[str, tuple[str, str]] = {}
    if options.spatial_relations:
        for rel in graph.relations:
            if rel.subject in shown and rel.object in shown:
                relation_of[rel.subject] = ("inside" if rel.predicate == "inside" else "on top of", shown[rel.object])
    held = graph.held_object
    rooms = []
    for rid in sorted(graph.regions, key=lambda r: names[r]):
        region = graph.regions[rid]
        objects = graph.objects_in(rid) + ([held] if held is not None and rid == graph.robot.region_id else [])
        entries = _merge([(shown[o.id], o.id, _state(o), relation_of.get(o.id), o.held) for o in objects])
        if options.floors:
            entries = (ObjectText(name=FLOOR, ids=()), *entries)
        rooms.append(RoomText(name=names[rid], region_id=rid, objects=entries, unexplored=bool(region.frontiers)))
    robot_room = names.get(graph.robot.region_id or "", UNKNOWN_PLACE)
    return SceneView(
        rooms=tuple(rooms),
        robot_room=robot_room,
        held=shown[held.id] if held is not None else None,
        held_id=held.id if held is not None else None,
    )


def _shown_name(obj: ObjectNode, options: LanguageOptions) -> str:
    return obj.label if options.instance_ids else obj.category


def _state(obj: ObjectNode) -> str | None:
    return None if obj.open is None else ("open" if obj.open else "closed")


_Entry = tuple[str, str, str | None, tuple[str, str] | None, bool]
"""(shown name, object id, state, relation, held) of one object."""


def _merge(entries: Iterable[_Entry]) -> tuple[ObjectText, ...]:
    """One ObjectText per distinct (name, state, relation, held), sorted: instance labels stay single,
    class names with equal attributes merge into one counted entry."""
    groups: dict[tuple[str, str, tuple[str, str] | tuple[()], bool], list[str]] = {}
    for name, oid, state, relation, held in entries:
        groups.setdefault((name, state or "", relation or (), held), []).append(oid)
    return tuple(
        ObjectText(name=n, ids=tuple(ids), state=s or None, relation=r or None, held=h)
        for (n, s, r, h), ids in sorted(groups.items())
    )
