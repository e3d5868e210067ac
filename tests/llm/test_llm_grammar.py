"""Length bounds of the grammars local models decode with."""

from __future__ import annotations

import json

from more_agent.llm import FilterAnswer, PlanAnswer, RoomLabelAnswer
from more_agent.llm.answers import MomaPlanAnswer
from more_agent.llm.grammar import MAX_ITEMS, NAME_CHARS, bounded_schema, free_text_chars
from more_agent.llm.jsontext import json_schema_of


def test_names_and_lists_get_their_bounds_and_reasoning_its_share_of_the_answer() -> None:
    plan = bounded_schema(json_schema_of(PlanAnswer), max_tokens=1024)["properties"]
    assert plan["reasoning"]["maxLength"] == free_text_chars(1024) == 1000 and plan["skill"]["maxLength"] == NAME_CHARS
    moma = bounded_schema(json_schema_of(MomaPlanAnswer), max_tokens=512)["properties"]
    assert moma["analysis"]["maxLength"] == moma["reasoning"]["maxLength"] == (512 - 256) * 2 // 2
    assert free_text_chars(100) == 200 and free_text_chars(100_000) == 1000  # the floor, and llama.cpp's ceiling
    assert plan["arguments"]["maxItems"] == MAX_ITEMS and plan["arguments"]["items"]["maxLength"] == NAME_CHARS


def test_nested_definitions_are_bounded_and_the_original_is_untouched() -> None:
    original = json_schema_of(FilterAnswer)
    before = json.dumps(original, sort_keys=True)
    bounded = bounded_schema(original)
    assert json.dumps(original, sort_keys=True) == before
    room = bounded["$defs"]["RoomObjects"]["properties"]
    assert room["room"]["maxLength"] == NAME_CHARS and room["objects"]["maxItems"] == MAX_ITEMS
    assert bounded["properties"]["rooms"]["maxItems"] == MAX_ITEMS and bounded["properties"]["rooms"]["items"] == {
        "$ref": "#/$defs/RoomObjects"}
    assert bounded["required"] == original["required"] and bounded["additionalProperties"] is False


def test_existing_bounds_and_enums_are_kept() -> None:
    schema = {"type": "object", "properties": {
        "room": {"type": "string", "maxLength": 8}, "kind": {"type": "string", "enum": ["a", "b"]},
        "tags": {"type": "array", "items": {"type": "string"}, "maxItems": 2},
    }}
    props = bounded_schema(schema)["properties"]
    assert props["room"]["maxLength"] == 8 and "maxLength" not in props["kind"] and props["tags"]["maxItems"] == 2
    assert bounded_schema(json_schema_of(RoomLabelAnswer))["properties"]["room"]["maxLength"] == NAME_CHARS
