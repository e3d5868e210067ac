"""Finding the JSON object in a model's text answer, and JSON schemas of answer models.

Models without constrained decoding wrap JSON in prose or code fences, or add a trailing comment;
:func:`extract_json` finds the first complete JSON object anyway.
"""

from __future__ import annotations

import json
import re
from typing import Any

from pydantic import BaseModel

_FENCE = re.compile(r"```(?:json|JSON)?\s*\n?(.*?)```", re.S)
_DECODER = json.JSONDecoder(strict=False)
"""Accepts raw control characters (a newline) inside strings: llama.cpp's JSON grammar lets a model
write them in its reasoning, which the strict standard forbids."""


def _first_object(text: str) -> dict[str, Any] | None:
    """The first JSON object that decodes starting at some '{' in ``text``."""
    start = text.find("{")
    while start != -1:
        try:
            value, _ = _DECODER.raw_decode(text, start)
        except json.JSONDecodeError:
            value = None
        if isinstance(value, dict):
            return value
        start = text.find("{", start + 1)
    return None


def extract_json(text: str) -> dict[str, Any] | None:
    """The JSON object in ``text``: the whole text, else inside a code fence, else the first one in prose."""
    stripped = text.strip()
    try:
        value = _DECODER.decode(stripped)
    except json.JSONDecodeError:
        value = None
    if isinstance(value, dict):
        return value
    for block in _FENCE.findall(text):
        found = _first_object(block)
        if found is not None:
            return found
    return _first_object(text)


def json_schema_of(model: type[BaseModel]) -> dict[str, Any]:
    """The JSON schema of an answer model, as sent in ``response_format`` and keyed in the cache."""
    return model.model_json_schema()
