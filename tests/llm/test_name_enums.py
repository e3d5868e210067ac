"""Names a model cannot misspell: per-request enums in answer schemas, sent over HTTP and compiled into grammars."""

from __future__ import annotations

import json

import jsonschema
import pytest
from pydantic import ValidationError

from more_agent.llm import CacheMode, ChatMessage, LLMConfig, PlanAnswer, ask_validated, make_client
from more_agent.llm.answers import FilterAnswer, MomaPlanAnswer, RoomLabelAnswer
from more_agent.llm.config import NameEnums, StructuredOutput
from more_agent.llm.grammar import bounded_schema
from more_agent.llm.jsontext import json_schema_of
from more_agent.llm.name_enums import (
    constrains_names,
    constrains_positions,
    filter_answer_with_names,
    per_skill_answer,
    uses_name_enums,
    with_name_enums,
)
from more_agent.llm.parsing import parse_plan_answer
from more_agent.llm.usage import reasoning_tokens
from more_agent.skills import SKILLS
from tests.fakes.openai_server import FakeOpenAIServer, Reply

ROOMS = ["kitchen_0", "living_room_0"]
OBJECTS = ["floor", "fridge A", "apple A", "sofa A"]
NAMES = {"skill": [s.name for s in SKILLS], "arguments": ROOMS + OBJECTS}
MESSAGES = [ChatMessage(role="user", content="plan")]


def _answer(skill: str, *args: str) -> str:
    return json.dumps({"reasoning": "The apple must go into the fridge, so I take it first.", "skill": skill,
                       "arguments": list(args)})


def test_enums_are_sorted_deduplicated_and_keep_the_shape() -> None:
    schema = json_schema_of(with_name_enums(PlanAnswer, {**NAMES, "arguments": [*ROOMS, *OBJECTS, "floor"]}))
    plain = json_schema_of(PlanAnswer)
    assert schema["properties"]["arguments"]["items"]["enum"] == sorted(set(ROOMS + OBJECTS))
    assert schema["properties"]["skill"]["enum"] == sorted(s.name for s in SKILLS)
    assert schema["required"] == plain["required"] and list(schema["properties"]) == list(plain["properties"])
    assert schema["title"] == plain["title"] and "enum" not in schema["properties"]["reasoning"]
    assert with_name_enums(PlanAnswer, {"arguments": []}) is PlanAnswer  # no names: no empty enum


def test_name_enums_setting_per_backend() -> None:
    assert uses_name_enums(LLMConfig(), "llamacpp") and not uses_name_enums(LLMConfig(), "openai")
    assert uses_name_enums(LLMConfig(name_enums=NameEnums.ON), "openai")
    assert not uses_name_enums(LLMConfig(name_enums=NameEnums.OFF), "llamacpp")
    assert not constrains_names(object())


def test_openai_json_schema_carries_the_enums_and_a_misspelling_is_reasked(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    """Through the real local HTTP server: the request's schema enumerates the names; a server that
    ignores it and answers a misspelled name gets the re-ask naming the closest valid names."""
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"name_enums": NameEnums.ON}))
    assert constrains_names(client)
    fake_openai.push(Reply(_answer("go_to_and_grasp", "kitchen_0", "<object name_optional_1>")),
                     Reply(_answer("go_to_and_grasp", "kitchen_0", "apple A")))
    out = ask_validated(client, MESSAGES, with_name_enums(PlanAnswer, NAMES),
                        lambda a: parse_plan_answer(a, SKILLS, ROOMS, OBJECTS), purpose="plan")
    assert out.value.call == "go_to_and_grasp(kitchen_0, apple A)"
    first, second = fake_openai.requests
    sent = first.body["response_format"]["json_schema"]
    assert sent["name"] == "PlanAnswer" and sent["schema"]["properties"]["arguments"]["items"]["enum"] == sorted(
        ROOMS + OBJECTS)
    reask = second.body["messages"][-1]["content"]
    assert "unknown object '<object name_optional_1>'" in reask


def test_reask_names_the_closest_valid_names_without_structured_output(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    client = make_client("openai:gpt-4o", llm_config.model_copy(update={"structured_output": StructuredOutput.NEVER}))
    fake_openai.push(Reply(_answer("go_to_and_grasp", "kitchen_0", "aple A")), Reply(_answer("done")))
    ask_validated(client, MESSAGES, PlanAnswer, lambda a: parse_plan_answer(a, SKILLS, ROOMS, OBJECTS))
    assert "response_format" not in fake_openai.requests[0].body
    assert "closest valid names: apple A" in fake_openai.requests[1].body["messages"][-1]["content"]


@pytest.mark.real_llm
def test_the_llamacpp_grammar_of_a_small_scene_admits_only_its_names() -> None:
    """The GBNF grammar llama.cpp decodes with, built from the request's bounded schema (needs the
    'llamacpp' extra, hence the real_llm marker)."""
    from llama_cpp import llama_grammar
    schema = bounded_schema(json_schema_of(with_name_enums(MomaPlanAnswer, NAMES)))
    grammar = llama_grammar.json_schema_to_gbnf(json.dumps(schema))
    for name in [*ROOMS, *OBJECTS, "go_to_and_place_inside", "done"]:
        assert f'"\\"{name}\\""' in grammar, name
    assert "name_optional" not in grammar and "fridge B" not in grammar
    free = llama_grammar.json_schema_to_gbnf(json.dumps(bounded_schema(json_schema_of(MomaPlanAnswer))))
    assert '"\\"fridge A\\""' not in free


def test_reasoning_tokens_are_the_reasoning_share_of_the_answer(
    fake_openai: FakeOpenAIServer, llm_config: LLMConfig
) -> None:
    text = json.dumps({"analysis": "a" * 300, "reasoning": "r" * 100, "skill": "done", "arguments": []})
    fake_openai.push(Reply(text, completion_tokens=120))
    out = make_client("openai:gpt-4o", llm_config).complete(MESSAGES, schema=MomaPlanAnswer, purpose="plan")
    assert reasoning_tokens(out) == round(120 * 400 / len(text)) and 100 < reasoning_tokens(out) < 120


def test_filter_answers_enumerate_rooms_and_objects_in_their_nested_entries() -> None:
    """The filter answer is where SmolLM2 wrote '<object name_optional_1>': its nested names are enumerated."""
    schema = json_schema_of(filter_answer_with_names({"kitchen_0": [], "living_room_0": []}, OBJECTS))
    entry = schema["$defs"]["RoomObjects"]["properties"]
    assert entry["room"]["enum"] == ROOMS and entry["objects"]["items"]["enum"] == sorted(OBJECTS)
    assert schema["properties"]["rooms"]["items"] == {"$ref": "#/$defs/RoomObjects"}
    assert filter_answer_with_names({}, []) is FilterAnswer
    room = json_schema_of(with_name_enums(RoomLabelAnswer, {"room": ["kitchen", "bathroom"]}))
    assert room["properties"]["room"]["enum"] == ["bathroom", "kitchen"]


BY_KIND = {"room": ROOMS, "object": OBJECTS}


def _shapes(schema: dict) -> dict[str, dict]:
    """Skill name -> the properties of its answer shape in a per-skill union schema."""
    shapes = [schema["$defs"][ref["$ref"].rsplit("/", 1)[1]]["properties"] for ref in schema["anyOf"]]
    return {shape["skill"]["const"]: shape for shape in shapes}


def test_per_skill_answers_constrain_each_argument_position() -> None:
    """The skill table's parameter kinds by position: explore(room), go_to_and_grasp(room, object), done()."""
    model = per_skill_answer(MomaPlanAnswer, SKILLS, BY_KIND)
    schema = json_schema_of(model)
    shapes = _shapes(schema)
    assert sorted(shapes) == sorted(s.name for s in SKILLS) and schema["title"] == "MomaPlanAnswer"
    assert all(list(p) == ["analysis", "reasoning", "skill", "arguments"] for p in shapes.values())
    assert shapes["explore"]["arguments"]["prefixItems"] == [{"enum": ROOMS, "type": "string"}]
    assert [i["enum"] for i in shapes["go_to_and_grasp"]["arguments"]["prefixItems"]] == [ROOMS, sorted(OBJECTS)]
    assert shapes["done"]["arguments"]["maxItems"] == 0 and shapes["done"]["arguments"]["items"] == {"type": "string"}
    jsonschema.Draft202012Validator.check_schema(schema)  # a valid schema (no empty prefixItems)
    jsonschema.validate({"analysis": "", "reasoning": "", "skill": "done", "arguments": []}, schema)
    valid = {"analysis": "", "reasoning": "", "skill": "go_to_and_grasp", "arguments": ["kitchen_0", "apple A"]}
    model.model_validate(valid)
    for wrong in (["apple A", "kitchen_0"], ["kitchen_0"], ["kitchen_0", "apple A", "sofa A"]):
        with pytest.raises(ValidationError):
            model.model_validate({**valid, "arguments": wrong})
    with pytest.raises(ValidationError):
        model.model_validate({**valid, "skill": "explore"})  # explore takes one room
    early = _shapes(json_schema_of(per_skill_answer(PlanAnswer, SKILLS, {"room": ROOMS, "object": []})))
    assert sorted(early) == ["done", "explore"]  # nothing seen yet: no skill on an object can be named


def test_only_llamacpp_clients_get_positions() -> None:
    assert constrains_positions(make_client("llamacpp:smollm2", LLMConfig(cache_mode=CacheMode.REPLAY)))
    assert not constrains_positions(
        make_client("llamacpp:smollm2", LLMConfig(cache_mode=CacheMode.REPLAY, name_enums=NameEnums.OFF))
    )
    on = LLMConfig(cache_mode=CacheMode.REPLAY, name_enums=NameEnums.ON)
    assert constrains_names(make_client("openai:gpt-4o", on)) and not constrains_positions(
        make_client("openai:gpt-4o", on)
    )


@pytest.mark.real_llm
def test_the_per_skill_union_compiles_and_smollm2_answers_by_position() -> None:
    """The union compiles to a GBNF grammar (one alternative per skill, each position its kind's names, done's
    arguments empty), and SmolLM2 decoding with it answers an object where an object goes."""
    from llama_cpp import llama_grammar

    model = per_skill_answer(PlanAnswer, SKILLS, BY_KIND)
    grammar = llama_grammar.json_schema_to_gbnf(json.dumps(bounded_schema(json_schema_of(model))))
    rules = dict(line.split(" ::= ", 1) for line in grammar.splitlines() if " ::= " in line)
    assert rules["root"].count("alternative-") == len(SKILLS)
    assert rules["PlanAnswer-go-to-and-grasp-arguments-tuple-1"] == " | ".join(f'"\\"{o}\\""' for o in sorted(OBJECTS))
    assert rules["PlanAnswer-done-arguments"] == '"[" space  "]" space'
    client = make_client("llamacpp:smollm2", LLMConfig(cache_mode=CacheMode.OFF, max_tokens=256))
    messages = [ChatMessage(role="user", content="Kitchen_0 has fridge A and apple A. Grasp apple A. Answer JSON.")]
    answer = json.loads(client.complete(messages, schema=model, purpose="plan").text)
    model.model_validate(answer)
    skill = next(s for s in SKILLS if s.name == answer["skill"])
    kinds = [ROOMS if k == "room" else OBJECTS for k in skill.params]
    assert len(answer["arguments"]) == len(kinds) and all(a in k for a, k in zip(answer["arguments"], kinds))
