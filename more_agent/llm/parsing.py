"""Validating LLM answers against the skill API and the scene: next action, filtered scene, room label.

Every parser takes the raw answer (text, or the JSON object already extracted), is tolerant about
form (code fences, ``"action": "skill(a, b)"`` instead of skill + arguments, case and ``_``/space
differences in names) and strict about content: a name must exist. What cannot be used raises
:class:`~more_agent.llm.errors.InvalidAnswer` whose ``reason`` is written for the LLM to read on a
re-ask, naming the closest valid names.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable, Mapping, Sequence
from typing import Any

from more_agent.errors import closest_names
from more_agent.llm.answers import FilterResult, PlannedAction
from more_agent.llm.errors import InvalidAnswer
from more_agent.llm.jsontext import extract_json
from more_agent.llm.limits import MAX_NAME_CHARS, MAX_REASONING_CHARS, clip
from more_agent.skills import Skill

Answer = str | Mapping[str, Any]
"""An answer as text or as its JSON object."""

_CALL = re.compile(r"([A-Za-z_][\w]*)\s*\(([^()]*)\)")


def _norm(name: str) -> str:
    """Comparison form of a name: no quotes, lower case, runs of spaces/underscores as one space."""
    return re.sub(r"[\s_]+", " ", name.strip().strip("'\"`").strip()).lower()


def resolve_name(name: str, valid: Iterable[str]) -> str | None:
    """The valid name ``name`` refers to: exact, else the single one equal up to case/spaces/underscores."""
    valid = list(valid)
    if name in valid:
        return name
    matches = [v for v in valid if _norm(v) == _norm(name)]
    return matches[0] if len(matches) == 1 else None


def _check_length(name: str) -> str:
    """``name``, or InvalidAnswer when it is longer than any real name can be (``MAX_NAME_CHARS``)."""
    if len(name) > MAX_NAME_CHARS:
        raise InvalidAnswer(f"the name {clip(name, 40)!r} is over the limit of {MAX_NAME_CHARS} characters")
    return name


def _closest_hint(name: str, valid: Iterable[str]) -> str:
    """'; closest valid ...: a, b' or '' when nothing is close."""
    by_norm = {_norm(v): v for v in valid}
    close = closest_names(_norm(name), by_norm, n=3)
    return f"; closest valid names: {', '.join(by_norm[c] for c in close)}" if close else ""


def _as_object(answer: Answer) -> Mapping[str, Any] | None:
    """The JSON object of an answer, or None."""
    return answer if isinstance(answer, Mapping) else extract_json(answer)


def _split_args(args: str) -> list[str]:
    """Arguments of a call string, quotes and blanks removed."""
    return [a.strip().strip("'\"`").strip() for a in args.split(",")] if args.strip() else []


def _call_from_text(text: str, skill_names: Collection[str]) -> tuple[str, list[str]] | None:
    """The last ``skill(args)`` in prose whose name is a known skill."""
    calls = [(m.group(1), _split_args(m.group(2))) for m in _CALL.finditer(text)]
    known = [c for c in calls if resolve_name(c[0], skill_names) is not None]
    return known[-1] if known else None


def _skill_and_args(answer: Answer, skill_names: Collection[str]) -> tuple[str, list[str], str]:
    """(skill, arguments, reasoning) from any accepted answer form."""
    obj = _as_object(answer)
    if obj is None:
        call = _call_from_text(answer if isinstance(answer, str) else "", skill_names)
        if call is None:
            raise InvalidAnswer(
                'no JSON object found; answer with {"reasoning": ..., "skill": ..., "arguments": [...]}'
            )
        return call[0], call[1], ""
    reasoning = str(obj.get("reasoning", ""))
    skill, args = obj.get("skill"), obj.get("arguments", [])
    if skill is None and isinstance(obj.get("action"), str):
        skill, args = obj["action"], []
    if not isinstance(skill, str) or not skill.strip():
        raise InvalidAnswer('the answer has no "skill" (a skill name as a string)')
    if isinstance(args, str):
        args = _split_args(args)
    if not isinstance(args, list) or not all(isinstance(a, str) for a in args):
        raise InvalidAnswer('"arguments" must be a list of room/object names (strings)')
    written = _CALL.fullmatch(skill.strip())
    if written is not None and not args:
        return written.group(1), _split_args(written.group(2)), reasoning
    return skill.strip().removesuffix("()"), [a.strip() for a in args], reasoning


def _bounded_skill_and_args(answer: Answer, skill_names: Collection[str]) -> tuple[str, list[str], str]:
    """:func:`_skill_and_args` with every name checked against ``MAX_NAME_CHARS`` and the reasoning clipped."""
    name, args, reasoning = _skill_and_args(answer, skill_names)
    for n in (name, *args):
        _check_length(n)
    return name, args, clip(reasoning, MAX_REASONING_CHARS)


def parse_plan_answer(
    answer: Answer,
    skills: Sequence[Skill],
    valid_rooms: Collection[str],
    valid_objects: Collection[str],
) -> PlannedAction:
    """The action an answer names, validated: known skill, right arity, existing room and object names.

    Raises InvalidAnswer naming the problem and the closest valid names.
    """
    by_name = {s.name: s for s in skills}
    name, args, reasoning = _bounded_skill_and_args(answer, by_name)
    canonical = resolve_name(name, by_name)
    if canonical is None:
        raise InvalidAnswer(
            f"unknown skill {name!r}{_closest_hint(name, by_name)}; skills: {', '.join(s.signature for s in skills)}"
        )
    skill = by_name[canonical]
    if len(args) != len(skill.params):
        raise InvalidAnswer(f"{skill.signature} takes {len(skill.params)} argument(s), got {len(args)}: {args}")
    resolved: dict[str, str] = {}
    for kind, arg in zip(skill.params, args, strict=True):
        valid = valid_rooms if kind == "room" else valid_objects
        name_ok = resolve_name(arg, valid)
        if name_ok is None:
            raise InvalidAnswer(f"unknown {kind} {arg!r} in {canonical}({', '.join(args)}){_closest_hint(arg, valid)}")
        resolved[kind] = name_ok
    return PlannedAction(
        skill=canonical,
        arguments=tuple(resolved[k] for k in skill.params),
        room=resolved.get("room"),
        object=resolved.get("object"),
        reasoning=reasoning,
    )


def _filter_pairs(obj: Mapping[str, Any]) -> list[tuple[str, list[str]]]:
    """(room, objects) pairs from ``{"rooms": [{"room", "objects"}]}`` or ``{"rooms": {room: [objects]}}``."""
    rooms = obj.get("rooms")
    if isinstance(rooms, Mapping):
        items = list(rooms.items())
    elif isinstance(rooms, list) and all(isinstance(r, Mapping) for r in rooms):
        items = [(r.get("room", r.get("name")), r.get("objects", [])) for r in rooms]
    else:
        raise InvalidAnswer('expected {"rooms": [{"room": <room name>, "objects": [<object names>]}, ...]}')
    pairs = []
    for room, objects in items:
        if not isinstance(room, str) or not isinstance(objects, list) or not all(isinstance(o, str) for o in objects):
            raise InvalidAnswer('every entry of "rooms" needs a "room" name and an "objects" list of names')
        pairs.append((room, objects))
    return pairs


def parse_filter_answer(answer: Answer, scene: Mapping[str, Collection[str]]) -> FilterResult:
    """The rooms and objects an answer keeps, restricted to names in ``scene`` (room -> its objects).

    An object listed under the wrong (or an unknown) room is kept in its own room when that is
    unambiguous; other unknown names are dropped and reported, never raised. Raises InvalidAnswer
    only when the answer has no usable structure.
    """
    obj = _as_object(answer)
    if obj is None:
        raise InvalidAnswer('no JSON object found; answer with {"rooms": [{"room": ..., "objects": [...]}]}')
    home: dict[str, list[str]] = {}
    for name, objects in scene.items():
        for o in objects:
            home.setdefault(o, []).append(name)
    kept: dict[str, list[str]] = {}
    unknown_rooms: list[str] = []
    unknown_objects: list[str] = []
    for room_name, objects in _filter_pairs(obj):
        room = resolve_name(room_name, scene) if len(room_name) <= MAX_NAME_CHARS else None
        if room is None:
            unknown_rooms.append(clip(room_name, MAX_NAME_CHARS))
        else:
            kept.setdefault(room, [])
        for o_name in objects:
            if len(o_name) > MAX_NAME_CHARS:
                unknown_objects.append(clip(o_name, MAX_NAME_CHARS))
                continue
            in_room = resolve_name(o_name, scene[room]) if room is not None else None
            anywhere = in_room or resolve_name(o_name, home)
            target = room if in_room else (home[anywhere][0] if anywhere and len(home[anywhere]) == 1 else None)
            if anywhere is None or target is None:
                unknown_objects.append(o_name)
            elif anywhere not in kept.setdefault(target, []):
                kept[target].append(anywhere)
    return FilterResult(
        rooms={r: tuple(objs) for r, objs in kept.items()},
        unknown_rooms=tuple(unknown_rooms),
        unknown_objects=tuple(unknown_objects),
    )


def parse_room_label(answer: Answer, labels: Collection[str] | None = None) -> str:
    """The room label of an answer (``{"room": ...}`` or a bare word), one of ``labels`` when given.

    Without ``labels`` the label is lower-cased with ``_`` for spaces. Raises InvalidAnswer.
    """
    obj = _as_object(answer)
    raw = obj.get("room") if obj is not None else (answer.strip().rstrip(".!") if isinstance(answer, str) else None)
    if not isinstance(raw, str) or not raw.strip() or len(raw.split()) > 4:
        raise InvalidAnswer('expected {"room": <room type>}')
    _check_length(raw)
    if labels is None:
        return _norm(raw).replace(" ", "_")
    label = resolve_name(raw, labels)
    if label is None:
        raise InvalidAnswer(
            f"unknown room type {raw.strip()!r}{_closest_hint(raw, labels)}; choose one of: {', '.join(labels)}"
        )
    return label
