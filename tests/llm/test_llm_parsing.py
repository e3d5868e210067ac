"""Answer parsing and validation: JSON extraction, plan / filter / room answers, prices."""

from __future__ import annotations

import pytest

from more_agent.llm import (
    InvalidAnswer,
    ModelPrice,
    PlannedAction,
    extract_json,
    parse_filter_answer,
    parse_plan_answer,
    parse_room_label,
)
from more_agent.llm.usage import price_of
from more_agent.skills import SKILLS

ROOMS = ["kitchen_0", "living_room_0", "garden_0"]
OBJECTS = ["fridge_a", "apple_a", "apple_b", "countertop_a", "sofa_a"]
SCENE = {"kitchen_0": ["fridge_a", "apple_a", "countertop_a"], "living_room_0": ["sofa_a", "apple_b"], "garden_0": []}


def plan(answer: object) -> PlannedAction:
    return parse_plan_answer(answer, SKILLS, ROOMS, OBJECTS)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('{"a": 1}', {"a": 1}),
        ('Here:\n```json\n{"a": {"b": [1, 2]}}\n```', {"a": {"b": [1, 2]}}),
        ('I pick {"a": "x}"} because {bad', {"a": "x}"}),
        ("{not json} then {\"a\": 2}", {"a": 2}),
        ("no json at all", None),
        ("[1, 2]", None),
    ],
)
def test_extract_json(text: str, expected: object) -> None:
    assert extract_json(text) == expected


def test_valid_plan_answers_in_every_accepted_form() -> None:
    expected = PlannedAction("go_to_and_grasp", ("kitchen_0", "apple_a"), "kitchen_0", "apple_a", "apple is here")
    assert plan({"reasoning": "apple is here", "skill": "go_to_and_grasp", "arguments": ["kitchen_0", "apple_a"]}) == expected
    assert plan('{"reasoning": "apple is here", "action": "go_to_and_grasp(kitchen_0, apple_a)"}') == expected
    assert plan('```json\n{"reasoning": "apple is here", "skill": "Go_To_And_Grasp", "arguments": ["Kitchen 0", "\'apple_a\'"]}\n```') == expected
    from_prose = plan("First navigate(kitchen_0, fridge_a) was done, so now go_to_and_grasp(kitchen_0, apple_a).")
    assert from_prose.call == "go_to_and_grasp(kitchen_0, apple_a)" and from_prose.reasoning == ""
    done = plan({"reasoning": "all placed", "skill": "done()", "arguments": []})
    assert done.skill == "done" and done.arguments == () and done.room is None and done.object is None
    explore = plan({"reasoning": "", "skill": "explore", "arguments": ["garden_0"]})
    assert explore.room == "garden_0" and explore.object is None


def test_hallucinated_object_names_the_closest_valid_ones() -> None:
    with pytest.raises(InvalidAnswer) as info:
        plan({"reasoning": "", "skill": "go_to_and_grasp", "arguments": ["kitchen_0", "apple_c"]})
    reason = info.value.reason
    assert "unknown object 'apple_c'" in reason and "apple_a" in reason and "apple_b" in reason
    assert "fridge_a" not in reason


@pytest.mark.parametrize(
    ("answer", "message"),
    [
        ({"reasoning": "", "skill": "go_to_and_grab", "arguments": ["kitchen_0", "apple_a"]}, "closest valid names: go_to_and_grasp"),
        ({"reasoning": "", "skill": "navigate", "arguments": ["apple_a"]}, r"navigate\(room, object\) takes 2 argument"),
        ({"reasoning": "", "skill": "explore", "arguments": ["kitchn"]}, "unknown room 'kitchn'.*kitchen_0"),
        ({"reasoning": "", "skill": "navigate", "arguments": ["kitchen_0", 3]}, "list of room/object names"),
        ({"reasoning": "no skill"}, 'no "skill"'),
        ("I am not sure what to do.", "no JSON object found"),
    ],
)
def test_invalid_plan_answers(answer: object, message: str) -> None:
    with pytest.raises(InvalidAnswer, match=message):
        plan(answer)


def test_filter_keeps_known_names_and_reports_unknown() -> None:
    answer = {
        "rooms": [
            {"room": "kitchen_0", "objects": ["fridge_a", "apple_a", "apple_z"]},
            {"room": "Living Room 0", "objects": ["apple_b"]},
            {"room": "garden_0", "objects": []},
            {"room": "attic_0", "objects": ["sofa_a"]},
        ]
    }
    result = parse_filter_answer(answer, SCENE)
    assert dict(result.rooms) == {
        "kitchen_0": ("fridge_a", "apple_a"),
        "living_room_0": ("apple_b", "sofa_a"),
        "garden_0": (),
    }
    assert result.unknown_rooms == ("attic_0",) and result.unknown_objects == ("apple_z",)
    assert result.objects == ("fridge_a", "apple_a", "apple_b", "sofa_a")


def test_filter_accepts_a_mapping_and_moves_misplaced_objects() -> None:
    result = parse_filter_answer('{"rooms": {"kitchen_0": ["sofa_a", "fridge_a"]}}', SCENE)
    assert dict(result.rooms) == {"kitchen_0": ("fridge_a",), "living_room_0": ("sofa_a",)}
    with pytest.raises(InvalidAnswer, match="expected"):
        parse_filter_answer({"relevant": ["fridge_a"]}, SCENE)
    with pytest.raises(InvalidAnswer, match="no JSON object"):
        parse_filter_answer("kitchen and fridge", SCENE)


def test_room_labels() -> None:
    labels = ["kitchen", "living_room", "bathroom"]
    assert parse_room_label({"room": "Living Room"}, labels) == "living_room"
    assert parse_room_label("Kitchen.", labels) == "kitchen"
    assert parse_room_label('{"room": "Dining Room"}') == "dining_room"
    with pytest.raises(InvalidAnswer, match="closest valid names: bathroom"):
        parse_room_label({"room": "bathrom"}, labels)
    with pytest.raises(InvalidAnswer):
        parse_room_label("This region looks like it could be a kitchen or a pantry", labels)


def test_prices() -> None:
    assert price_of("gpt-4o-2024-08-06") == price_of("gpt-4o")
    assert price_of("gpt-4o-mini-2024-07-18") == ModelPrice(input_per_m=0.15, output_per_m=0.60)
    assert price_of("qwen2.5") is None
    assert price_of("qwen2.5", {"qwen2.5": ModelPrice(input_per_m=0, output_per_m=0)}) is not None


def test_raw_newlines_inside_reasoning_are_accepted() -> None:
    """llama.cpp's JSON grammar admits raw control characters in strings; a long analysis has them."""
    from more_agent.llm import extract_json

    text = '{"analysis": "line one\nline two", "reasoning": "r", "skill": "done", "arguments": []}'  # a raw newline
    assert "\n" in text and extract_json(text) == {"analysis": "line one\nline two", "reasoning": "r", "skill": "done",
                                                    "arguments": []}
