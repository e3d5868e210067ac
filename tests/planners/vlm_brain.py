"""A scripted stand-in for a VLM: answers the BUMBLE questions by reading their text (object lists, captions).

``RearrangeVLM`` solves "put item X inside container Y" tasks: it remembers every object named in
the questions it saw (with its attributes), decides open / grasp / place / explore / done like
``tests.planners.brain.RearrangeBrain``, picks the frame whose caption names its target and the
mark listed for it, explores frames in turn, and judges explorations by whether its target is now known.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from typing import Any

_ENTRY = re.compile(r"([A-Za-z_]+ [A-Z]+)(?: \[([^\]]*)\])?")


def step(skill: str, subtask: str) -> str:
    """A step answer as the prompt asks for it."""
    return json.dumps({"reasoning": "scripted", "subtask": subtask, "skill": skill})


def user_text(body: dict[str, Any]) -> str:
    """The text of every user message of a request (a re-ask's conversation included), images left out."""
    texts = []
    for m in body["messages"]:
        if m["role"] == "user":
            content = m["content"]
            texts += [content] if isinstance(content, str) else [p["text"] for p in content if p["type"] == "text"]
    return "\n".join(texts)


def kind(body: dict[str, Any]) -> str:
    """Which BUMBLE question a request is: plan, landmark, object, explore, verify, filter."""
    system = body["messages"][0]["content"]
    for key, name in (("carry out a subtask", "landmark"), ("the object a mobile robot moves to", "object"),
                      ("explores next", "explore"), ("has just explored", "verify"), ("Remove every object", "filter")):
        if key in system:
            return name
    return "plan"


class RearrangeVLM:
    """Puts each item inside its container (labels, e.g. {'apple A': 'fridge A'}), then done."""

    def __init__(self, goal: Mapping[str, str]) -> None:
        self.goal = dict(goal)
        self.known: dict[str, list[str]] = {}
        self.target = ""
        self.placing: str | None = None
        self.opened: set[str] = set()
        """Containers the robot opened (frames in memory may still show them closed)."""
        self.explored = 0

    def _learn(self, text: str) -> None:
        for line in text.splitlines():
            if re.match(r"^(Frame \d+: |\d+: )", line):
                for m in _ENTRY.finditer(line.split(": ", 1)[1]):
                    self.known[m.group(1)] = [a.strip() for a in (m.group(2) or "").split(",") if a.strip()]

    def __call__(self, body: dict[str, Any]) -> str:
        text = user_text(body)
        self._learn(text)
        question = kind(body)
        if question == "filter":
            scene = text.split("Scene:\n", 1)[1].split("\n\n", 1)[0]
            room = scene.split(":", 1)[0]
            keep = [o for o in set(self.goal) | set(self.goal.values()) if o in scene]
            return json.dumps({"rooms": [{"room": room, "objects": keep}]})
        if question == "landmark":
            frames = re.findall(r"^Frame (\d+): (.*)$", text, re.M)
            shows = [int(k) for k, objs in frames if self.target in {m.group(1) for m in _ENTRY.finditer(objs)}]
            return json.dumps({"reasoning": "", "frame": shows[0] if shows else 1})
        if question == "object":
            marks = re.findall(r"^(\d+): ([A-Za-z_]+ [A-Z]+)", text, re.M)
            return json.dumps({"reasoning": "", "mark": next((int(k) for k, o in marks if o == self.target), 1)})
        if question == "explore":
            frames = re.findall(r"^Frame (\d+):", text, re.M)
            self.explored += 1
            return json.dumps({"reasoning": "", "frame": int(frames[self.explored % len(frames)])})
        if question == "verify":
            return json.dumps({"reasoning": "scripted", "achieved": self.target in self.known})
        opened = re.search(r"Last feedback: .*(?:opened (.+)|; (.+) is already open)$", text, re.M)
        if opened:
            self.opened.add(opened.group(1) or opened.group(2))
        held = re.search(r"Robot: holding (.+)\.", text)
        return self.plan(None if held is None or held.group(1) == "nothing" else held.group(1))

    def plan(self, held: str | None) -> str:
        if self.placing is not None and held is None:  # the last placement worked
            self.known[self.placing] = [f"inside {self.goal[self.placing]}"]
        self.placing = None
        for container in sorted(set(self.goal.values())):
            if "closed" in self.known.get(container, []) and container not in self.opened and held is None:
                self.target = container
                return step("go_to_and_open", f"open {container}")
        if held in self.goal:
            self.target, self.placing = self.goal[held], held
            return step("go_to_and_place_inside", f"put {held} inside {self.target}")
        todo = [i for i in sorted(self.goal) if f"inside {self.goal[i]}" not in self.known.get(i, [])]
        if not todo:
            return step("done", "the task is complete")
        for item in todo:
            if item in self.known and held is None:
                self.target = item
                return step("go_to_and_grasp", f"grasp {item}")
        self.target = todo[0]
        return step("explore", f"find {todo[0]}")
