"""Length bounds for grammar-constrained JSON answers of local models (llama.cpp).

llama.cpp compiles an answer's JSON schema into a grammar, which fixes the shape of the answer but
not its length: a small model at temperature 0 can repeat one sentence inside a string, or one name
inside a list, until ``max_tokens`` cuts the JSON off and the answer is lost. The grammar therefore
gets the bounds that the answer schemas leave open: names at most :data:`NAME_CHARS` characters,
lists at most :data:`MAX_ITEMS` items, and free text (:data:`FREE_TEXT_FIELDS`: the reasoning and
analysis a model writes before its command) at most what the answer budget leaves for it
(:func:`free_text_chars`: ``max_tokens`` less room for the command, shared among the free-text
fields). That is no cap the model is asked to respect (the prompts set none; none of the papers
limits reasoning): it only makes an answer that would run into ``max_tokens`` close its JSON
instead of being cut off. A bounded answer still follows the original schema. Only grammars built
here (in process, or through llama.cpp's server) get the bounds; the schema sent to hosted APIs and
keyed in the cache is unchanged.
"""

from __future__ import annotations

from typing import Any

from more_agent.llm.constants import DEFAULT_MAX_TOKENS

NAME_CHARS = 64
"""Longest string for names (rooms, objects, skills, room types): the longest scene name is about 40."""

FREE_TEXT_FIELDS = frozenset({"reasoning", "analysis"})
"""Answer fields holding free text rather than a name; they share the answer budget (:func:`free_text_chars`)."""

COMMAND_TOKENS = 256
"""Tokens of the answer budget kept for everything but the free text (keys, names, the command)."""

CHARS_PER_TOKEN = 2
"""Characters per token assumed for free text (prose runs about 4, a copied scene list about 2: SmolLM2 copies)."""

MIN_TEXT_CHARS = 200
"""Free text is never bounded below this, however small ``max_tokens`` is."""

MAX_TEXT_CHARS = 1000
"""... nor above this: llama.cpp refuses (and llama-cpp-python 0.3 then crashes on) grammars whose
repetitions exceed its limit; a 2,304-character bound did."""

MAX_ITEMS = 16
"""Longest list: arguments of a skill, rooms kept by the filter, relevant objects in one room."""


def free_text_chars(max_tokens: int, fields: int = 1) -> int:
    """Longest free-text string when ``fields`` free-text fields share an answer of ``max_tokens`` tokens."""
    share = (max_tokens - COMMAND_TOKENS) * CHARS_PER_TOKEN // max(1, fields)
    return min(MAX_TEXT_CHARS, max(MIN_TEXT_CHARS, share))


def bounded_schema(schema: Any, max_tokens: int = DEFAULT_MAX_TOKENS) -> Any:
    """A copy of ``schema`` with ``maxLength`` on unbounded strings and ``maxItems`` on unbounded arrays;
    free text gets its share of an answer of ``max_tokens`` tokens."""
    return _bounded(schema, "", free_text_chars(max_tokens, _free_fields(schema)))


def _free_fields(schema: Any) -> int:
    """Free-text fields of one answer: of the schema's properties, or for a union of answer shapes
    (:func:`~more_agent.llm.name_enums.per_skill_answer`) of the shape in ``$defs`` that has most."""
    if not isinstance(schema, dict):
        return 0
    shapes = [schema, *schema.get("$defs", {}).values()]
    return max(sum(name in FREE_TEXT_FIELDS for name in s.get("properties", {})) for s in shapes)


def _bounded(schema: Any, field: str, text_chars: int) -> Any:
    """:func:`bounded_schema` of a (sub)schema; ``field`` is the property name it belongs to."""
    if isinstance(schema, list):
        return [_bounded(item, field, text_chars) for item in schema]
    if not isinstance(schema, dict):
        return schema
    out: dict[str, Any] = {}
    for key, value in schema.items():
        if key == "properties" and isinstance(value, dict):
            out[key] = {name: _bounded(sub, name, text_chars) for name, sub in value.items()}
        elif key == "$defs" and isinstance(value, dict):
            out[key] = {name: _bounded(sub, "", text_chars) for name, sub in value.items()}
        else:
            out[key] = _bounded(value, field, text_chars)
    if out.get("type") == "string" and "maxLength" not in out and "enum" not in out and "const" not in out:
        out["maxLength"] = text_chars if field in FREE_TEXT_FIELDS else NAME_CHARS
    if out.get("type") == "array" and "maxItems" not in out:
        out["maxItems"] = MAX_ITEMS
    return out
