"""Whole LLM-planner episodes against a fake OpenAI server, through the real client, cache and parsers."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from more_agent.eval.episode import run_episode
from more_agent.eval.episode_folder import STEPS_FILE
from more_agent.llm import CacheMode, LLMConfig, load_llm_config, make_client
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.sim.instantiate import instantiate
from more_agent.skills import INVALID
from tests.fakes.openai_server import Close, Delay, Status
from tests.planners.brain import BrainServer, RearrangeBrain, plan

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"
GOAL = {
    "pack_of_ground_beef A": "fridge A", "cup_of_yogurt A": "fridge A", "bottle_of_cooking_oil A": "bottom_cabinet A",
    "canned_food A": "bottom_cabinet A", "box_of_cereal A": "bottom_cabinet A",
}
SPEC = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=0, planner="more", llm="openai:fake-model")


class DoneBrain:
    """Labels rooms, keeps no object in the filter, answers plan prompts from ``plans``, then done()."""

    def __init__(self, *plans: str) -> None:
        self.plans = list(plans)

    def __call__(self, body: dict[str, Any]) -> str:
        user = body["messages"][-1]["content"]
        if "Possible room types" in user:
            return json.dumps({"room": "kitchen"})
        if "Remove every object" in body["messages"][0]["content"]:
            return json.dumps({"rooms": []})
        return self.plans.pop(0) if self.plans else plan("done")


ANSWER_S = 10.0
"""The requests' deadline: a scripted answer took over 0.5 s on a CI worker loaded by the others' numba compiles
(fresh clone, 3 workers on 2 cores). The timeout test sets its own."""


def _config(server: BrainServer, tmp_path: Path, **kw: Any) -> LLMConfig:
    base = dict(base_url=server.base_url, api_key="sk-test", timeout_s=ANSWER_S, max_retries=0, backoff_initial_s=0.01,
                backoff_max_s=0.02, cache_path=tmp_path / "cache.sqlite")
    return LLMConfig(**{**base, **kw})


def _run(server: BrainServer, tmp_path: Path, spec: EpisodeSpec = SPEC, **kw: Any) -> EpisodeRecord:
    client = make_client("openai:fake-model", _config(server, tmp_path, **kw))
    planner = LLMPlanner(PLANNER_CONFIGS[spec.planner], LLMClients(client, client, "openai:fake-model"))
    return run_episode(spec, planner=planner, out_dir=tmp_path / "ep")


@pytest.fixture
def done_server() -> Iterator[BrainServer]:
    with BrainServer(DoneBrain()) as server:
        yield server


def test_successful_episode_solves_the_task(tmp_path: Path) -> None:
    with BrainServer(RearrangeBrain(GOAL)) as server:
        record = _run(server, tmp_path)
    assert record.success and record.all_goals_met and record.done_called
    assert record.task_progress == 1.0
    assert record.actions[-1].name == "done"
    usage = record.llm_usage  # a request repeated within the episode is answered from the cache
    assert usage.calls == len(server.requests) + usage.cache_hits and usage.prompt_tokens == 100 * usage.calls
    assert record.low_level_steps > 11 and len(record.trajectory) > 10
    fridge = instantiate(SPEC.task, SPEC.scene, SPEC.seed).scope["electric_refrigerator.n.01_1"]
    assert fridge in record.observed_objects
    steps = (tmp_path / "ep" / STEPS_FILE).read_text().splitlines()
    assert len(steps) == record.high_level_steps
    first = json.loads(steps[0])
    # MORE filters: the planner saw a strict subset of the scene, the brain kept only task objects.
    assert len(first["planning_scene"]) < len(first["scene"]) and "breakfast_table" not in first["planning_scene"]
    assert json.loads((tmp_path / "ep" / "episode.json").read_text())["success"] is True


def test_hallucinated_object_is_reasked_then_used(tmp_path: Path) -> None:
    with BrainServer(DoneBrain(plan("go_to_and_grasp", "kitchen_0", "unicorn A"))) as server:
        record = _run(server, tmp_path)
    assert record.error is None and record.done_called and record.high_level_steps == 1
    reask = server.requests[-1].body["messages"]
    assert "unknown object 'unicorn A'" in reask[-1]["content"] and reask[-2]["role"] == "assistant"


def test_malformed_output_after_reasks_is_an_invalid_action_fed_back(tmp_path: Path) -> None:
    with BrainServer(DoneBrain(*["I would go to the kitchen."] * 3)) as server:
        record = _run(server, tmp_path)
    assert record.error is None and record.high_level_steps == 2
    assert record.actions[0].name == INVALID and not record.actions[0].ok
    assert record.actions[1].name == "done"
    last_plan = server.requests[-1].body["messages"][-1]["content"]
    assert "invalid(" in last_plan and "failed" in last_plan  # the failure is in the history


def test_timeout_ends_the_episode_with_the_error_recorded(done_server: BrainServer, tmp_path: Path) -> None:
    done_server.push(Delay(3.0))
    record = _run(done_server, tmp_path, timeout_s=0.3)
    assert record.error is not None and "LLMTimeout" in record.error
    assert record.traceback is None and record.high_level_steps == 0 and not record.success
    assert record.goal_conditions  # the outcome is still evaluated
    assert json.loads((tmp_path / "ep" / "episode.json").read_text())["error"] == record.error


def test_rate_limit_then_success(done_server: BrainServer, tmp_path: Path) -> None:
    done_server.push(Status(429, retry_after=0))
    record = _run(done_server, tmp_path, max_retries=2)
    assert record.error is None and record.done_called
    assert len(done_server.requests) == record.llm_usage.calls + 1


def test_server_gone_mid_episode_keeps_everything_so_far(tmp_path: Path) -> None:
    brain = RearrangeBrain(GOAL)
    calls = {"plan": 0}

    def dying(body: dict[str, Any]) -> Any:
        if "Previous actions" in body["messages"][-1]["content"]:
            calls["plan"] += 1
            if calls["plan"] == 3:
                threading.Thread(target=server.stop, daemon=True).start()
                return Close()
        return brain(body)

    with BrainServer(dying) as server:
        record = _run(server, tmp_path, max_retries=1)
    assert record.error is not None and "LLMConnectionError" in record.error
    assert record.high_level_steps == 2 and all(a.ok for a in record.actions)
    assert record.llm_usage.calls > 0 and record.task_progress >= 0.0 and record.goal_conditions


def test_repeated_run_is_served_from_the_cache(done_server: BrainServer, tmp_path: Path) -> None:
    first = _run(done_server, tmp_path)
    asked = len(done_server.requests)
    second = _run(done_server, tmp_path)
    assert len(done_server.requests) == asked  # nothing new was asked
    assert second.llm_usage.cache_hits == second.llm_usage.calls == first.llm_usage.calls > 0
    assert [a.name for a in second.actions] == [a.name for a in first.actions]


def test_replay_miss_fails_clearly(done_server: BrainServer, tmp_path: Path) -> None:
    record = _run(done_server, tmp_path, cache_mode=CacheMode.REPLAY)
    assert record.error is not None and "ReplayMiss" in record.error and "replay: no cached answer" in record.error
    assert done_server.requests == [] and record.high_level_steps == 0


def test_moma_llm_names_objects_by_class_and_does_not_filter(tmp_path: Path) -> None:
    with BrainServer(DoneBrain(plan("go_to_and_open", "kitchen_0", "fridge"))) as server:
        record = _run(server, tmp_path, spec=SPEC.model_copy(update={"planner": "moma-llm"}))
    assert record.error is None and record.actions[0].ok and record.actions[0].feedback == "opened fridge A"
    assert not any("Remove every object" in r.body["messages"][0]["content"] for r in server.requests)
    prompt = server.requests[-1].body["messages"]
    scene = prompt[-1]["content"].split("Rooms and the objects found in them so far:\n", 1)[1].split("\nRooms with", 1)[0]
    assert "opened fridge" in scene and "fridge A" not in scene and "closed bottom_cabinet, closed bottom_cabinet" in scene
    assert "Analysis" not in prompt[0]["content"] and '"analysis"' in prompt[0]["content"]


def test_room_llm_labels_rooms_and_is_recorded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """--room-llm: room prompts go to the room model (the paper's gpt-3.5-turbo), the rest to the planning model."""
    from more_agent.commands._common import use_room_llm
    from more_agent.planners.llm_planner import make_clients

    with BrainServer(DoneBrain()) as server:
        monkeypatch.delenv("MORE_AGENT_ROOM_MODEL", raising=False)
        use_room_llm("openai:gpt-3.5-turbo")  # what the CLI option does
        clients = make_clients("openai:gpt-4o", load_llm_config(overrides=_config(server, tmp_path).model_dump(exclude={"room_model"})))
        record = run_episode(SPEC, planner=LLMPlanner(PLANNER_CONFIGS["more"], clients), out_dir=tmp_path / "ep")
    assert record.error is None and (record.llm, record.room_llm) == ("openai:gpt-4o", "openai:gpt-3.5-turbo")
    models = {("Possible room types" in r.body["messages"][-1]["content"], r.body["model"]) for r in server.requests}
    assert models == {(True, "gpt-3.5-turbo"), (False, "gpt-4o")}
