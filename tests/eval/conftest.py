"""Real episodes written once per session for the viewer and report tests: MORE against a scripted
LLM (through the fake OpenAI server and the real client) and the oracle, both on the tiny kitchen scene."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from more_agent.eval.viewer import run_episode_with_viewer
from more_agent.llm import LLMConfig, make_client
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.records import EpisodeRecord, EpisodeSpec
from tests.planners.brain import BrainServer, plan

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"
EVIL = '</script><script>window.__pwned = 1</script><b id="bold">bold</b>'
"""LLM output that would run script or make markup if the page did not escape it."""


class ScriptedBrain:
    """Labels rooms, filters to nothing, opens the fridge, answers one plan prompt with ``EVIL`` text
    (no JSON: re-asked), then calls done() with ``EVIL`` as its reasoning."""

    def __init__(self) -> None:
        self.plans = [plan("go_to_and_open", "kitchen_0", "fridge A"), EVIL]

    def __call__(self, body: dict[str, Any]) -> str:
        if "Possible room types" in body["messages"][-1]["content"]:
            return json.dumps({"room": "kitchen"})
        if "Remove every object" in body["messages"][0]["content"]:
            return json.dumps({"rooms": [{"room": "kitchen_0", "objects": ["fridge A"]}]})
        if self.plans:
            return self.plans.pop(0)
        return json.dumps({"reasoning": EVIL, "skill": "done", "arguments": []})


@dataclass(frozen=True)
class Episode:
    """An episode folder, its record and (for LLM planners) the requests the fake server received."""

    dir: Path
    record: EpisodeRecord
    requests: list[dict[str, Any]]


@pytest.fixture(scope="session")
def llm_episode(tmp_path_factory: pytest.TempPathFactory) -> Episode:
    root = tmp_path_factory.mktemp("llm_episode")
    spec = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=0, planner="more", llm="openai:fake-model")
    with BrainServer(ScriptedBrain()) as server:
        config = LLMConfig(base_url=server.base_url, api_key="sk-test", timeout_s=5, max_retries=0,
                           cache_path=root / "cache.sqlite")
        client = make_client("openai:fake-model", config)
        planner = LLMPlanner(PLANNER_CONFIGS["more"], LLMClients(client, client, "openai:fake-model"))
        record = run_episode_with_viewer(spec, planner=planner, out_dir=root / "ep")
        requests = [r.body for r in server.requests]
    return Episode(root / "ep", record, requests)


@pytest.fixture(scope="session")
def oracle_episode(tmp_path_factory: pytest.TempPathFactory) -> Episode:
    root = tmp_path_factory.mktemp("oracle_episode")
    record = run_episode_with_viewer(EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=0), out_dir=root / "ep")
    return Episode(root / "ep", record, [])
