"""A fake LLM for one MORE decision: labels every room a kitchen, keeps the objects named in ``keep``
and plans ``skill(room, object)`` (through tests/fakes/openai_server.py and the real client)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from more_agent.llm import LLMConfig, make_client
from more_agent.planners.llm_planner import LLMClients

SPEC = "openai:fake-model"


class DecisionBrain:
    def __init__(self, keep: list[str], skill: str, obj: str) -> None:
        self.keep, self.skill, self.obj = keep, skill, obj

    def __call__(self, body: dict[str, Any]) -> str:
        system, user = body["messages"][0]["content"], body["messages"][-1]["content"]
        if "Possible room types" in user:
            return json.dumps({"room": "kitchen"})
        room = self._room_of(user)
        if "Remove every object" in system:
            return json.dumps({"rooms": [{"room": room, "objects": self.keep}]})
        return json.dumps({"reasoning": "the cup is on the table", "skill": self.skill, "arguments": [room, self.obj]})

    def _room_of(self, user: str) -> str:
        for line in user.split("Scene:\n", 1)[-1].splitlines():
            if f" {self.obj}" in line or line.endswith(self.obj):
                return re.split(r"[ :]", line, maxsplit=1)[0]
        return "kitchen_0"


def clients(base_url: str, cache: Path) -> LLMClients:
    config = LLMConfig(base_url=base_url, api_key="sk-test", timeout_s=5, max_retries=0, cache_path=cache)
    client = make_client(SPEC, config)
    return LLMClients(client, client, SPEC)
