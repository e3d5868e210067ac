"""A scripted stand-in for the LLM: answers the room, filter and plan prompts by reading them.

``BrainServer`` is the fake OpenAI server of ``tests.fakes`` answering from a function of the
request instead of a fixed script (script items pushed first still win, which is how tests inject
timeouts, 429s and bad answers at a chosen point). ``RearrangeBrain`` solves "put item X inside
container Y" tasks from the scene text alone (MORE's, or MoMa-LLM's by class): open the containers,
grasp, place, explore, done.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from tests.fakes.openai_server import FakeOpenAIServer, ScriptItem

_OBJECT = re.compile(r"([A-Za-z_]+(?: [A-Z]+)?)(?: \(x\d+\))?(?: \[([^\]]*)\])?")


class BrainServer(FakeOpenAIServer):
    """Fake OpenAI server whose answer, once the pushed script is used up, is ``brain(request body)``."""

    def __init__(self, brain: Callable[[dict[str, Any]], ScriptItem | str]) -> None:
        super().__init__(responder=brain)
        self.brain = brain


@dataclass(frozen=True)
class SceneText:
    """What a plan prompt says: rooms -> {object name: attributes}, the robot's room, the held object."""

    rooms: dict[str, dict[str, list[str]]]
    unexplored: list[str]
    robot_room: str
    held: str | None


def parse_prompt(user: str) -> SceneText:
    """Read the scene and robot lines of a filter or plan prompt."""
    scene = user.split("Scene:\n", 1)[1].split("\n\n", 1)[0]
    rooms: dict[str, dict[str, list[str]]] = {}
    unexplored = []
    for line in scene.splitlines():
        head, _, body = line.partition(": ")
        name = head.replace(" (unexplored areas)", "")
        if head != name:
            unexplored.append(name)
        objects = {} if body == "no objects seen" else {
            m.group(1): [a.strip() for a in (m.group(2) or "").split(",") if a.strip()]
            for m in _OBJECT.finditer(body) if m.group(1).strip()
        }
        rooms[name] = objects
    robot = re.search(r"Robot: in (\S+), holding (.+)\.", user)
    room, held = (robot.group(1), robot.group(2)) if robot else ("", "nothing")
    return SceneText(rooms, unexplored, room, None if held == "nothing" else held)


MOMA_ROOMS = "Rooms and the objects found in them so far:\n"
"""Where MoMa-LLM's planning prompt lists the rooms (:mod:`more_agent.planners.moma_encoding`)."""

_MOMA_OBJECT = re.compile(r"(?:(opened|closed) )?([A-Za-z_]+)(?: \[([^\]]*)\])?")


def parse_moma_prompt(user: str) -> SceneText:
    """Read MoMa-LLM's planning prompt: objects by class, their state a prefix ('opened fridge'), the
    rooms with unexplored space leading out, the robot's room and the held object."""
    rooms: dict[str, dict[str, list[str]]] = {}
    for line in user.split(MOMA_ROOMS, 1)[1].split("\nRooms with", 1)[0].splitlines():
        room, _, body = line.removeprefix("- ").partition(": ")
        rooms[room] = {
            m.group(2): [a for a in ({"opened": "open"}.get(m.group(1) or "", m.group(1)), m.group(3)) if a]
            for m in _MOMA_OBJECT.finditer(body.strip("[].")) if m.group(2)
        }
    leading_out = re.search(r"Rooms with unexplored space leading out of them: \[(.*)\]\.", user)
    unexplored = re.findall(r"(\S+) \(", leading_out.group(1)) if leading_out else []
    room = re.search(r"You are in the (\S+), standing next to", user)
    held = re.search(r"You are holding: (.+)\.", user)
    holding = held.group(1) if held else "nothing"
    return SceneText(rooms, unexplored, room.group(1) if room else "", None if holding == "nothing" else holding)


def by_class(label: str) -> str:
    """An instance label as MoMa-LLM's text names it: 'fridge A' -> 'fridge'."""
    return re.sub(r" [A-Z]+$", "", label)


def plan(skill: str, *args: str) -> str:
    """A plan answer as the prompt asks for it."""
    return json.dumps({"reasoning": "scripted", "skill": skill, "arguments": list(args)})


class RearrangeBrain:
    """Puts each item inside its container (labels, e.g. {'apple A': 'fridge A'}), then calls done()."""

    def __init__(self, goal: Mapping[str, str], room_label: str = "kitchen") -> None:
        self.goal = dict(goal)
        self.room_label = room_label
        self.explored = 0

    def __call__(self, body: dict[str, Any]) -> str:
        system, user = body["messages"][0]["content"], body["messages"][-1]["content"]
        if "Possible room types" in user:
            return json.dumps({"room": self.room_label})
        if "Remove every object" in system:
            return self.filter(parse_prompt(user))
        if MOMA_ROOMS in user:  # MoMa-LLM's encoding names objects by class
            return self.plan(parse_moma_prompt(user), {by_class(k): by_class(v) for k, v in self.goal.items()})
        return self.plan(parse_prompt(user), self.goal)

    def filter(self, s: SceneText) -> str:
        keep = set(self.goal) | set(self.goal.values())
        return json.dumps({"rooms": [{"room": r, "objects": [o for o in objs if o in keep]} for r, objs in s.rooms.items()]})

    def plan(self, s: SceneText, goal: Mapping[str, str]) -> str:
        where = {o: r for r, objs in s.rooms.items() for o in objs}
        attrs = {o: a for objs in s.rooms.values() for o, a in objs.items()}
        for container in sorted(set(goal.values())):
            if container in where and "closed" in attrs[container] and s.held is None:
                return plan("go_to_and_open", where[container], container)
        if s.held in goal:
            target = goal[s.held]
            if target in where:
                return plan("go_to_and_place_inside", where[target], target)
        todo = [i for i in sorted(goal) if f"inside {goal[i]}" not in attrs.get(i, [])]
        if not todo:
            return plan("done")
        for item in todo:
            if item in where and s.held is None:
                return plan("go_to_and_grasp", where[item], item)
        rooms = s.unexplored or list(s.rooms)
        self.explored += 1
        return plan("explore", rooms[self.explored % len(rooms)])
