"""Names a model cannot misspell: answer schemas whose name fields enumerate the valid names of one request.

A grammar (llama.cpp) or a strict JSON schema (OpenAI's ``json_schema`` structured output) fixes
the shape of an answer, not its names: a small model fills a well-formed answer with
``<object name_optional_1>``. PARTNR (Chang et al. 2024) reports that constraining generation to
valid actions on observed objects "greatly reduces the hallucinations". :func:`with_name_enums`
derives, per request, a subclass of an answer model whose name fields are ``Literal`` unions of the
names this request may use (skills, rooms, object labels, room types), so the JSON schema sent
carries them as ``enum`` lists and the decoder cannot leave them.

Whether a client's requests get the enums is the ``name_enums`` setting of the LLM config
(:class:`~more_agent.llm.config.NameEnums`): by default only for llama.cpp, whose grammar always
applies; for OpenAI-compatible endpoints it is opt-in, since not every server honours a schema (those
that do not fall back to text, and an unknown name then goes through the re-ask path, which names
the closest valid names). The enum changes the request, hence the cache key: runs recorded without
it replay without it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, Literal, TypeVar, cast, get_origin

from pydantic import BaseModel, create_model

from more_agent.llm.answers import FilterAnswer, RoomObjects
from more_agent.llm.config import LLMConfig, NameEnums


def uses_name_enums(config: LLMConfig, backend_kind: str) -> bool:
    """Whether requests to a ``backend_kind`` backend carry name enums under ``config``."""
    if config.name_enums is NameEnums.AUTO:
        return backend_kind == "llamacpp"
    return config.name_enums is NameEnums.ON


def constrains_names(client: object) -> bool:
    """Whether ``client`` (a ChatClient, or a wrapper forwarding its attributes) wants name enums;
    clients that say nothing (scripted test clients) do not."""
    return bool(getattr(client, "name_enums", False))


M = TypeVar("M", bound=BaseModel)


def with_name_enums(model: type[M], names: Mapping[str, Iterable[str]]) -> type[M]:
    """A subclass of ``model`` whose fields in ``names`` (``str`` or ``list[str]``) accept only those names.

    Names are deduplicated and sorted, so equal name sets give equal schemas (and cache keys). A field
    with no names keeps its free type: an empty enum would admit no answer at all.
    """
    fields: dict[str, Any] = {}
    for field, values in names.items():
        valid = sorted(set(values))
        if not valid:
            continue
        info = model.model_fields[field]
        choice: Any = Literal.__getitem__(tuple(valid))
        fields[field] = (list[choice] if get_origin(info.annotation) is list else choice, info)
    if not fields:
        return model
    return cast(type[M], create_model(model.__name__, __base__=model, __doc__=model.__doc__, **fields))


def filter_answer_with_names(rooms: Iterable[str], objects: Iterable[str]) -> type[FilterAnswer]:
    """MORE's filter answer whose room and object names are enumerated (the nested room entries too)."""
    entry: Any = with_name_enums(RoomObjects, {"room": rooms, "objects": objects})
    if entry is RoomObjects:
        return FilterAnswer
    entries: Any = list[entry]
    info = FilterAnswer.model_fields["rooms"]
    return create_model(
        FilterAnswer.__name__, __base__=FilterAnswer, __doc__=FilterAnswer.__doc__, rooms=(entries, info)
    )
