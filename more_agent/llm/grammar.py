"""Length bounds for grammar-constrained JSON answers of local models (llama.cpp).

llama.cpp compiles an answer's JSON schema into a grammar, which fixes the shape of the answer but
not its length: a small model at temperature 0 can repeat one name inside a list until ``max_tokens``
cuts the JSON off. The grammar therefore gets the bounds that the answer schemas leave open: names at
most :data:`NAME_CHARS` characters, lists at most :data:`MAX_ITEMS` items. Free text
(:data:`FREE_TEXT_FIELDS`: the reasoning and analysis a model writes before its command) has no
length cap: none of the papers limits it, and ``max_tokens`` bounds it. A bounded answer still
follows the original schema. Only grammars built here (in process, or through
llama.cpp's server) get the bounds; the schema sent to hosted APIs and keyed in the cache is unchanged.
"""

from __future__ import annotations

from typing import Any

NAME_CHARS = 64
"""Longest string for names (rooms, objects, skills, room types): the longest scene name is about 40."""

FREE_TEXT_FIELDS = frozenset({"reasoning", "analysis"})
"""Answer fields holding free text rather than a name: never bounded here (``max_tokens`` bounds them)."""

MAX_ITEMS = 16
"""Longest list: arguments of a skill, rooms kept by the filter, relevant objects in one room."""


def bounded_schema(schema: Any, field: str = "") -> Any:
    """A copy of ``schema`` with ``maxLength`` on unbounded strings and ``maxItems`` on unbounded arrays.

    ``field`` is the property name the (sub)schema belongs to; free-text fields stay unbounded.
    """
    if isinstance(schema, list):
        return [bounded_schema(item, field) for item in schema]
    if not isinstance(schema, dict):
        return schema
    out: dict[str, Any] = {}
    for key, value in schema.items():
        if key == "properties" and isinstance(value, dict):
            out[key] = {name: bounded_schema(sub, name) for name, sub in value.items()}
        elif key == "$defs" and isinstance(value, dict):
            out[key] = {name: bounded_schema(sub) for name, sub in value.items()}
        else:
            out[key] = bounded_schema(value, field)
    if out.get("type") == "string" and "maxLength" not in out and "enum" not in out and field not in FREE_TEXT_FIELDS:
        out["maxLength"] = NAME_CHARS
    if out.get("type") == "array" and "maxItems" not in out:
        out["maxItems"] = MAX_ITEMS
    return out
