"""Every step of an LLM planner, the scene text agrees with the scene graph it was written from and with
the actions already taken.

Short seeded episodes (three in the default run, eighteen in the slow one) in the two-room fixture (``store_produce``: fruit in a paper bag, a fridge, a door),
driven through the real planner (:class:`LLMPlanner`: its prompts, parsers, filter and subpolicies) by a
scripted LLM in the process that answers each prompt with a random valid choice read from the prompt. At every
step the text is read back as the LLM reads it and compared with the graph (every room, object,
attribute and relation in the text is in the graph and everything the text promises to show is in
the text) and with the history (a successful grasp shows the item held, a placement shows the item
where it was put, an opening or closing shows the new state), including actions older than the
paper's history of five.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from more_agent.eval.episode import reset_planner, run_episode
from more_agent.llm.completion import ChatMessage, Completion, TokenUsage
from more_agent.llm.prompts import HISTORY_LAST_N, LASTING_SKILLS
from more_agent.planners.base import Step
from more_agent.planners.language import FLOOR, HELD, SceneView, room_names
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.records import ActionRecord, EpisodeSpec, HistoryMode
from more_agent.scene_graph import SceneGraph
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.scene import load_scene
from tests.planners.brain import plan

TINY = Path(__file__).parents[1] / "fixtures" / "tiny_scene.json"
TASK = "store_produce"
STEPS = 12
"""High-level steps per episode before the scripted LLM calls done()."""

Entry = tuple[str, str | None, tuple[str, str] | None, bool]
"""(name, state, relation, held) of one object as the text shows it."""

_LINE = re.compile(r"^(?P<room>\S+?)(?P<unexplored> \(unexplored areas\))?: (?P<body>.*)$")
_ENTRY = re.compile(r"^(?P<name>[^\[(]+?)(?: \(x(?P<count>\d+)\))?(?: \[(?P<attrs>[^\]]*)\])?$")


def _split(body: str) -> list[str]:
    """A room line's entries: split at ', ' outside brackets."""
    parts, depth, current = [], 0, ""
    for ch in body:
        depth += {"[": 1, "]": -1}.get(ch, 0)
        current += ch
        if depth == 0 and current.endswith(", "):
            parts.append(current[:-2])
            current = ""
    return [*parts, current]


def read_text(text: str) -> dict[str, tuple[bool, Counter[Entry]]]:
    """Room -> (unexplored, entries) of a scene text, each object as often as its count says."""
    rooms: dict[str, tuple[bool, Counter[Entry]]] = {}
    for line in text.splitlines():
        m = _LINE.match(line)
        assert m is not None, f"not a room line: {line!r}"
        entries: Counter[Entry] = Counter()
        for part in [] if m["body"] == "no objects seen" else _split(m["body"]):
            e = _ENTRY.match(part)
            assert e is not None, f"not an object entry: {part!r} in {line!r}"
            attrs = [a for a in (e["attrs"] or "").split(", ") if a]
            state = next((a for a in attrs if a in ("open", "closed")), None)
            relation = next(((a[:9], a[10:]) if a.startswith("on top of ") else ("inside", a[7:])
                             for a in attrs if a.startswith(("inside ", "on top of "))), None)
            held = HELD in attrs
            assert len(attrs) == (state is not None) + (relation is not None) + held, f"unknown attribute in {part!r}"
            entries[(e["name"], state, relation, held)] += int(e["count"] or 1)
        assert m["room"] not in rooms, f"room {m['room']} listed twice"
        rooms[m["room"]] = (m["unexplored"] is not None, entries)
    return rooms


def from_graph(graph: SceneGraph, planner: str) -> dict[str, tuple[bool, Counter[Entry]]]:
    """What the text of ``graph`` must say under ``planner``'s language options, worked out from the graph."""
    options = PLANNER_CONFIGS[planner].language
    names = room_names(graph)
    shown = {o.id: (o.label if options.instance_ids else o.category) for o in graph.objects.values()}
    relation = {r.subject: ("inside" if r.predicate == "inside" else "on top of", shown[r.object])
                for r in graph.relations if options.spatial_relations and r.object in shown}
    held = graph.held_object
    rooms = {}
    for rid, region in graph.regions.items():
        objects = [o for o in graph.objects.values() if o.region_id == rid or (o.held and rid == graph.robot.region_id)]
        entries = Counter((shown[o.id], None if o.open is None else ("open" if o.open else "closed"),
                           relation.get(o.id), o.held) for o in objects)
        if options.floors:
            entries[(FLOOR, None, None, False)] += 1
        rooms[names[rid]] = (bool(region.frontiers), entries)
    assert held is None or graph.robot.region_id is not None, "the robot holds something outside every region"
    return rooms


@dataclass
class Deeds:
    """What the successful actions so far did, from their feedback (labels, as the world names them)."""

    held: str | None = None
    placed: dict[str, tuple[str, str]] = field(default_factory=dict)
    """Item -> ('inside' | 'on top of', label of the container / support, or 'the floor of <room>')."""
    state: dict[str, str] = field(default_factory=dict)
    """Openable -> 'open' | 'closed'."""


def deeds(history: list[Any]) -> Deeds:
    """Replay the feedback of the successful actions ('grasped apple A', 'placed apple A inside fridge A')."""
    d = Deeds()
    for a in history:
        if not a.ok:
            continue
        if m := re.fullmatch(r"grasped (.+)", a.feedback):  # what rests on it stays there, in the robot's hand
            d.held = m[1]
            d.placed.pop(m[1], None)
        elif m := re.fullmatch(r"placed (.+?) (inside|on) (.+)", a.feedback):
            assert m[1] == d.held, f"placed {m[1]} while holding {d.held}"
            d.held = None
            d.placed[m[1]] = ("inside" if m[2] == "inside" else "on top of", m[3])
        elif m := re.fullmatch(r"(opened|closed) (.+)", a.feedback):
            d.state[m[2]] = "open" if m[1] == "opened" else "closed"
    return d


def check_deeds(view: SceneView, graph: SceneGraph, history: list[Any], planner: str, regions_seen: set[str]) -> None:
    """The text shows what the robot did: the item it grasped as held, each placed item where it went,
    each opened or closed object in that state. An object may be missing only when the graph lost
    regions it had (``regions_seen``): it holds the regions the robot can reach on its map, and an item
    the robot put down in a doorway can cut the map."""
    options = PLANNER_CONFIGS[planner].language
    rooms = read_text(view.text())
    entries = [e for _, found in rooms.values() for e in found]
    name = {o.label: (o.label if options.instance_ids else o.category) for o in graph.objects.values()}

    def present(obj: str, deed: str) -> bool:
        if obj in name:
            return True
        assert regions_seen - set(graph.regions), f"{obj} ({deed}) is missing from the graph, though no region is"
        return False

    did = deeds(history)
    held = [e for e in entries if e[3]]
    if did.held is None:
        assert not held and view.held is None, f"nothing was grasped, yet the text shows {held}"
    else:
        assert view.held == name[did.held] and held and all(e[0] == name[did.held] for e in held), (
            f"{did.held} was grasped: the text must show it held\n{view.text()}")
        assert any(e[3] for e in rooms[view.robot_room][1]), "the held item is listed in the robot's room"
    for item, (how, where) in did.placed.items():
        if not present(item, f"placed {how} {where}"):
            continue
        shown = [e for e in entries if e[0] == name[item] and not e[3]]
        assert shown, f"{item} was placed {how} {where} and is missing from the text\n{view.text()}"
        on_floor = where.startswith("the floor of ")  # floors are no graph objects
        if options.spatial_relations and (on_floor or present(where, f"{item} placed {how} it")):
            want = None if on_floor else (how, name[where])
            assert any(e[2] == want for e in shown), f"{item} placed {how} {where}, the text shows {shown}"
    for obj, state in did.state.items():
        if present(obj, state):
            assert any(e[0] == name[obj] and e[1] == state for e in entries), f"{obj} was left {state}\n{view.text()}"
    regions_seen.update(graph.regions)


class RandomBrain:
    """Answers every prompt with a random valid choice read from the prompt; done() after ``STEPS`` steps."""

    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)

    def __call__(self, body: dict[str, Any]) -> str:
        system, user = body["messages"][0]["content"], body["messages"][-1]["content"]
        if "Possible room types" in user:
            return json.dumps({"room": str(self.rng.choice(["kitchen", "living_room", "pantry_room"]))})
        rooms = read_text(user.split("Scene:\n", 1)[1].split("\n\n", 1)[0])
        if "Remove every object" in system:
            return json.dumps({"rooms": [
                {"room": r, "objects": [e[0] for e in found if self.rng.random() < 0.5]}
                for r, (_, found) in rooms.items() if self.rng.random() < 0.7
            ]})
        steps = [int(n) for n in re.findall(r"^(\d+)\. ", user.split("Previous actions:\n", 1)[1], re.M)]
        if max(steps, default=0) >= STEPS:
            return plan("done")
        return self.plan(rooms, holding="holding nothing" not in user)

    def plan(self, rooms: dict[str, tuple[bool, Counter[Entry]]], holding: bool) -> str:
        objects = [(r, e) for r, (_, found) in rooms.items() for e in found if not e[3]]
        openable = [(r, e) for r, e in objects if e[1] is not None]
        things = [(r, e) for r, e in objects if e[0] != FLOOR and e[1] is None]
        choices = [("explore", r, None) for r in rooms]
        choices += [("navigate", r, e) for r, e in objects if e[0] != FLOOR]
        if holding:
            choices += [(f"go_to_and_place_{how}", r, e) for r, e in objects for how in ("inside", "ontop")] * 3
        else:
            choices += [("go_to_and_grasp", r, e) for r, e in things] * 6
            choices += [("go_to_and_open" if e[1] == "closed" else "go_to_and_close", r, e) for r, e in openable] * 6
        skill, room, entry = choices[self.rng.integers(len(choices))]
        return plan(skill, room) if entry is None else plan(skill, room, entry[0])


class ScriptedClient:
    """An LLM client answering from :class:`RandomBrain` in the process (no server, no cache: fast)."""

    model = "scripted"

    def __init__(self, brain: RandomBrain) -> None:
        self.brain = brain

    def complete(self, messages: list[ChatMessage], *, schema: object = None, purpose: str = "", attempt: int = 0) -> Completion:
        text = self.brain({"messages": list(messages)})
        return Completion(text=text, parsed=json.loads(text), model=self.model, usage=TokenUsage(), cost_usd=0.0,
                          cost_known=True, cached=False, latency_s=0.0, attempts=1, purpose=purpose)


class CheckedPlanner(LLMPlanner):
    """The LLM planner, checking each step's scene texts against its graph and its history."""

    regions_seen: set[str]
    """Every region id of the episode's graphs so far."""

    old_deeds = 0
    """Steps whose check covered a successful grasp, place, open or close older than the last five actions."""

    def observe(self) -> None:
        if not self.history:
            self.regions_seen = set()
        self.old_deeds += any(a.ok and a.name in LASTING_SKILLS for a in self.history[:-HISTORY_LAST_N])
        super().observe()
        graph, view = self._graph(), self._view()
        assert read_text(view.text()) == from_graph(graph, self.name), (
            f"step {len(self.history)}: the scene text disagrees with its graph\n{view.text()}")
        check_deeds(view, graph, self.history, self.name, self.regions_seen)

    def decide(self) -> Step:
        action = super().decide()
        full, planning = read_text(self._view().text()), read_text((self.planning_view or self._view()).text())
        assert self._view().robot_room in planning or self._view().robot_room not in full
        for room, (unexplored, entries) in planning.items():
            assert full[room][0] == unexplored and not entries - full[room][1], f"the filter invented {room}: {entries}"
            assert all(e in entries for e in full[room][1] if e[3]), "the filter dropped the held item"
        return action


PLANNERS = ("more", "moma-llm-sr", "moma-llm")
"""Instance ids with relations, classes with relations, classes alone."""

DEFAULT_SEEDS = {"more": (3,), "moma-llm-sr": (0,), "moma-llm": (1,)}
"""The default run's episodes: one per planner, seeds whose random choices between them grasp, place,
open and close, and act again after the history forgot it (the slow run takes seeds 0-5 of each)."""


def checked_episodes(seeds: dict[str, tuple[int, ...]]) -> tuple[Counter[str], int]:
    """Run each planner's episodes under :class:`CheckedPlanner`: the successful actions' verbs
    ('grasped', 'placed', 'opened' ...) counted, and the steps whose check covered an old deed."""
    done = Counter[str]()
    old_deeds = 0
    for planner, planner_seeds in seeds.items():
        for seed in planner_seeds:
            client = ScriptedClient(RandomBrain(seed))
            # MORE's plan prompt for every language view: the brain reads its scene text (MoMa-LLM's
            # own prompt encodes the same view differently, tests/planners/test_moma_encoding.py).
            config = PLANNER_CONFIGS[planner].model_copy(update={"prompt": "more"})
            agent = CheckedPlanner(config, LLMClients(client, client, "scripted"))
            record = run_episode(EpisodeSpec(task=TASK, scene=str(TINY), seed=seed, planner=planner), planner=agent)
            assert record.error is None and record.traceback is None, record.traceback or record.error
            assert record.history == "paper"
            done.update(a.feedback.split(" ", 1)[0] for a in record.actions if a.ok)
            old_deeds += agent.old_deeds
    return done, old_deeds


def test_scene_text_agrees_with_graph_and_history_every_step() -> None:
    done, old_deeds = checked_episodes(DEFAULT_SEEDS)
    # The random episodes did exercise what the text must show, also after the history forgot the deed.
    assert done["grasped"] >= 4 and done["placed"] >= 3 and done["opened"] + done["closed"] >= 4, done
    assert old_deeds >= 10


@pytest.mark.slow
def test_scene_text_agrees_with_graph_and_history_over_many_seeds() -> None:
    done, old_deeds = checked_episodes({planner: tuple(range(6)) for planner in PLANNERS})
    assert done["grasped"] >= 18 and done["placed"] >= 12 and done["opened"] + done["closed"] >= 12, done
    assert old_deeds >= 30


class RecordingBrain(RandomBrain):
    """A RandomBrain that keeps the plan prompts it was asked."""

    def __init__(self, seed: int) -> None:
        super().__init__(seed)
        self.plan_prompts: list[str] = []

    def __call__(self, body: dict[str, Any]) -> str:
        user = body["messages"][-1]["content"]
        if "Previous actions:" in user:
            self.plan_prompts.append(user)
        return super().__call__(body)


@pytest.mark.parametrize("history", ["paper", "lasting"])
def test_the_history_option_reaches_the_plan_prompt(history: HistoryMode) -> None:
    """An old successful grasp is in the prompt's history only with ``lasting``; a failed one always."""
    brain = RecordingBrain(0)
    client = ScriptedClient(brain)
    agent = LLMPlanner(PLANNER_CONFIGS["more"], LLMClients(client, client, "scripted"))
    instance = instantiate_in_scene(TASK, load_scene(TINY), seed=0)
    reset_planner(agent, instance, GoalChecker(instance), history=history)
    old = [
        ActionRecord(step=0, name="go_to_and_grasp", arguments=["kitchen_0", "apple A"], ok=True, feedback="grasped apple A"),
        ActionRecord(step=1, name="explore", arguments=["kitchen_0"], ok=False, feedback="no unexplored area"),
    ]
    agent.history = old + [ActionRecord(step=k, name="explore", arguments=["kitchen_0"], ok=True) for k in range(2, 8)]
    agent.observe()
    agent.decide()
    shown = brain.plan_prompts[-1].split("Previous actions:\n", 1)[1]
    assert ("1. go_to_and_grasp(kitchen_0, apple A) -> succeeded: grasped apple A" in shown) == (history == "lasting")
    assert "2. explore(kitchen_0) -> failed: no unexplored area" in shown and "8. explore(kitchen_0)" in shown
