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

Where the grammar compiles it (llama.cpp: :func:`constrains_positions`), a planning answer goes
further: :func:`per_skill_answer` makes it a union of one shape per skill, whose ``skill`` is that
skill's name and whose ``arguments`` are a tuple holding, at each position, the names of the kind the
skill table gives it (``explore(room)``, ``go_to_and_grasp(room, object)``, ``done()``), so a model
can neither give an object where a room goes nor a wrong number of arguments. OpenAI's strict
``json_schema`` refuses a union at the root, so OpenAI-compatible endpoints keep the flat enums.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Literal, TypeVar, Union, cast, get_origin

from pydantic import BaseModel, RootModel, create_model
from pydantic.fields import FieldInfo

from more_agent.llm.answers import FilterAnswer, RoomObjects
from more_agent.llm.config import LLMConfig, NameEnums
from more_agent.skills import ParamKind, Skill


def uses_name_enums(config: LLMConfig, backend_kind: str) -> bool:
    """Whether requests to a ``backend_kind`` backend carry name enums under ``config``."""
    if config.name_enums is NameEnums.AUTO:
        return backend_kind == "llamacpp"
    return config.name_enums is NameEnums.ON


def constrains_names(client: object) -> bool:
    """Whether ``client`` (a ChatClient, or a wrapper forwarding its attributes) wants name enums;
    clients that say nothing (scripted test clients) do not."""
    return bool(getattr(client, "name_enums", False))


NO_ITEMS: dict[str, Any] = {"items": {"type": "string"}}
"""Items of an argument list that holds nothing (``done()``, ``maxItems`` 0): without any, llama.cpp's
grammar reads the list as "any JSON array" (and JSON Schema forbids an empty ``prefixItems``)."""


def constrains_positions(client: object) -> bool:
    """Whether ``client`` wants name enums per skill and argument position (:func:`per_skill_answer`): a
    client with name enums whose backend is llama.cpp, whose grammar compiles the union."""
    backend = getattr(client, "backend", None)
    return constrains_names(client) and getattr(backend, "kind", "") == "llamacpp"


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


def per_skill_answer(
    model: type[BaseModel], skills: Sequence[Skill], names: Mapping[ParamKind, Iterable[str]]
) -> type[BaseModel]:
    """``model`` (an answer with ``skill`` and ``arguments``) as a union of one shape per skill: the skill's
    name as a constant, and as arguments a tuple whose item ``i`` enumerates ``names`` of the skill's
    ``i``-th parameter kind. Fields before the command (the reasoning) keep their place and type. A skill
    with a parameter kind that has no name yet (no object seen) cannot be called in this request and is
    left out; ``done`` takes none and is always in."""
    valid = {kind: sorted(set(values)) for kind, values in names.items()}
    skill_info, arguments_info = model.model_fields["skill"], model.model_fields["arguments"]
    variants: list[Any] = []
    for skill in skills:
        if not all(valid.get(kind) for kind in skill.params):
            continue
        positions = tuple(Literal.__getitem__(tuple(valid[kind])) for kind in skill.params)
        arguments: Any = tuple.__class_getitem__(positions) if positions else tuple[()]
        info = arguments_info if positions else FieldInfo.merge_field_infos(arguments_info, json_schema_extra=NO_ITEMS)
        variants.append(
            create_model(
                f"{model.__name__}_{skill.name}",
                __base__=model,
                __doc__=f"{skill.signature}: {skill.description}",
                skill=(cast(Any, Literal.__getitem__((skill.name,))), skill_info),
                arguments=(arguments, info),
            )
        )
    union: Any = Union.__getitem__(tuple(variants)) if len(variants) > 1 else variants[0]
    return cast(type[BaseModel], create_model(model.__name__, __base__=RootModel[union], __doc__=model.__doc__))
