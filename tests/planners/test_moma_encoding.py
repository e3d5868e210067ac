"""MoMa-LLM's own scene encoding and the planning prompts: golden prompts per planner, names, enums."""

from __future__ import annotations

import pytest

from more_agent.eval.episode import reset_planner
from more_agent.llm import InvalidAnswer
from more_agent.planners.language import scene_view
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.planners.moma_encoding import distance_word, moma_history, moma_scene, without_state
from more_agent.planners.plan_prompts import PlanRequest, PlanState, plan_request
from more_agent.records import ActionRecord
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.scene import load_scene
from tests.planners.test_language import _check_snapshot, _obj, hand_made_graph
from tests.planners.test_scene_text_consistency import TINY, RandomBrain, ScriptedClient

HISTORY = [
    ActionRecord(step=0, name="explore", arguments=["kitchen_0"], ok=False, feedback="no unexplored area left"),
    *[ActionRecord(step=k, name="navigate", arguments=["kitchen_0", "table"], ok=True, feedback="at table A")
      for k in range(1, 6)],
    ActionRecord(step=6, name="go_to_and_grasp", arguments=["kitchen_0", "book"], ok=True, feedback="grasped book A"),
]


def _request(planner: str, *, name_enums: bool = False, by_position: bool = False) -> PlanRequest:
    config = PLANNER_CONFIGS[planner]
    graph = hand_made_graph()
    view = scene_view(graph, config.language)
    state = PlanState("Put the book on the sofa.", graph, view, view, HISTORY, "go_to_and_grasp: success", "paper")
    return plan_request(config.prompt, state, name_enums=name_enums, by_position=by_position)


def _prompt_text(request: PlanRequest) -> str:
    return "\n".join(f"[[{m['role']}]]\n{m['content']}" for m in request.messages)


@pytest.mark.parametrize("planner", ["more", "moma-llm", "moma-llm-sr"])
def test_golden_plan_prompts(planner: str) -> None:
    """The whole planning prompt of each LLM planner on the hand-made graph (update with MORE_AGENT_UPDATE_SNAPSHOTS=1)."""
    _check_snapshot(f"prompt_{planner}", _prompt_text(_request(planner)))


def test_moma_prompt_is_momas_encoding_not_mores() -> None:
    moma, sr = _prompt_text(_request("moma-llm")), _prompt_text(_request("moma-llm-sr"))
    assert "Scene:" not in moma and "fridge A" not in moma and "Analysis" not in _prompt_text(_request("more"))
    assert "- kitchen_0: [floor, apple, apple, closed cabinet, closed cabinet, opened fridge, table]." in moma
    assert "apple [inside fridge]" in sr and "apple [on top of table]" in sr and "[inside" not in moma
    assert "unexplored space leading out of them: [kitchen_0 (very close), unknown_room_0 (near)]" in moma
    assert "You are holding: book." in moma and "book" not in moma.split("Rooms and")[1].split("You are holding")[0]
    # the last five and the earlier failed one, as MoMa-LLM's history keeps them
    assert "Your 6 previous actions were: explore(kitchen_0) - failure, navigate(kitchen_0, table) - success" in moma


def test_nearby_objects_and_closed_doors_with_distance_words() -> None:
    graph = hand_made_graph()
    door = _obj("door B", "region_2", (13.0, 1.5), open_=False)
    far = _obj("plate A", "region_0", (4.5, 1.5))
    graph = graph.model_copy(update={"objects": {**graph.objects, door.id: door, far.id: far}})
    scene = moma_scene(graph, scene_view(graph, PLANNER_CONFIGS["moma-llm"].language))
    assert "plate" not in scene.nearby and "table" in scene.nearby  # 3 m away vs 0.7 m: MoMa-LLM's 2.5 m
    assert scene.closed_doors == (("living_room_0", "far"),)
    assert "Rooms with closed doors that might open up new space: [living_room_0 (far)]." in scene.text()
    assert [distance_word(d) for d in (0.5, 3.0, 12.0, 25.0)] == ["very close", "near", "far", "distant"]


def test_moma_answers_may_name_states_and_reason_first() -> None:
    request = _request("moma-llm")
    planned = request.validate(
        {"analysis": "The sofa is in the living room. " * 40, "reasoning": "I hold the book.",
         "skill": "go_to_and_place_ontop", "arguments": ["living_room_0", "sofa"]}
    )
    assert planned.call == "go_to_and_place_ontop(living_room_0, sofa)"
    assert request.validate({"analysis": "", "reasoning": "", "skill": "go_to_and_open",
                             "arguments": ["kitchen_0", "closed cabinet"]}).object == "cabinet"
    assert without_state("opened fridge") == "fridge" and without_state("opener") == "opener"
    with pytest.raises(InvalidAnswer, match="closest valid names: sofa"):
        request.validate({"analysis": "", "reasoning": "", "skill": "navigate", "arguments": ["living_room_0", "sofas"]})


def test_name_enums_list_exactly_the_names_of_the_request() -> None:
    free = _request("moma-llm").schema.model_json_schema()["properties"]
    assert "enum" not in free["skill"] and "enum" not in free["arguments"]["items"]
    schema = _request("moma-llm", name_enums=True).schema.model_json_schema()
    props = schema["properties"]
    assert list(props) == ["analysis", "reasoning", "skill", "arguments"]  # reasoning before the command
    assert "go_to_and_grasp" in props["skill"]["enum"] and "done" in props["skill"]["enum"]
    names = props["arguments"]["items"]["enum"]
    assert names == sorted({"kitchen_0", "living_room_0", "unknown_room_0", "floor", "apple", "book", "cabinet",
                            "fridge", "table", "door", "sofa"})
    assert "fridge A" not in names and schema["additionalProperties"] is False
    more = _request("more", name_enums=True).schema.model_json_schema()["properties"]["arguments"]["items"]["enum"]
    assert "fridge A" in more and "fridge" not in more


@pytest.mark.parametrize(("planner", "fridge"), [("more", "fridge A"), ("moma-llm", "fridge")])
def test_plan_requests_by_position_name_a_room_then_an_object(planner: str, fridge: str) -> None:
    """llama.cpp's form of the name enums: one answer shape per skill, each argument from its kind's names."""
    request = _request(planner, name_enums=True, by_position=True)
    schema = request.schema.model_json_schema()
    shapes = {d["properties"]["skill"]["const"]: d["properties"] for d in schema["$defs"].values()}
    rooms, objects = (p["enum"] for p in shapes["go_to_and_open"]["arguments"]["prefixItems"])
    assert "kitchen_0" in rooms and fridge in objects and "kitchen_0" not in objects and fridge not in rooms
    assert [p["enum"] for p in shapes["explore"]["arguments"]["prefixItems"]] == [rooms]
    assert (
        request.validate(
            {"analysis": "", "reasoning": "", "skill": "go_to_and_open", "arguments": ["kitchen_0", fridge]}
        ).call
        == f"go_to_and_open(kitchen_0, {fridge})"
    )


def test_history_line_when_nothing_was_done() -> None:
    assert moma_history([]) == "You have not acted yet."


def test_the_held_object_is_neither_in_a_room_nor_nearby() -> None:
    graph = hand_made_graph()
    scene = moma_scene(graph, scene_view(graph, PLANNER_CONFIGS["moma-llm"].language))
    assert all("book" not in objs for _, objs in scene.rooms) and "book" not in scene.nearby


@pytest.mark.parametrize(("planner", "task"), [
    ("moma-llm", "put every pomegranate inside the fridge; put every mango inside the fridge"),
    ("more", "put every pomegranate inside fridge A; put every mango inside fridge A"),
])
def test_moma_llm_gets_the_description_by_class(planner: str, task: str) -> None:
    """MoMa-LLM's text never shows 'fridge A', so its task says 'the fridge'; MORE's keeps the label."""
    instance = instantiate_in_scene("store_produce", load_scene(TINY), seed=0)
    client = ScriptedClient(RandomBrain(0))
    agent = LLMPlanner(PLANNER_CONFIGS[planner], LLMClients(client, client, "scripted"))
    reset_planner(agent, instance, GoalChecker(instance), history="paper")
    assert agent.task == task
