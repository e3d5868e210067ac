"""The language description a planner receives, as a template with ``$scope`` words.

The MORE paper's descriptions "include all task relevant details for the goal conditions" and name
specific instances with ``$`` words, replaced by the object's label. Our worlds hold instances its
authors never saw (the scenes' own furniture and objects), and bddl 3.6's goals differ from its text
in places. Two modes (``DESCRIPTION_MODES``):

- ``named`` (the default) applies the paper's own mechanism to our worlds: the paper's text, then the
  goal conditions it leaves out (``data/description_additions.json``, one audit of the 55 tasks),
  then every goal instance the world makes ambiguous (``sim.ambiguity``), named by its reserved label:
  the goal conditions that mention it ("To be exact: put money A on top of checkout_counter B"), and
  the instances a quantifier ranges over ("The plate(s) meant are plate A, plate B and plate C").
- ``paper`` keeps the paper's text verbatim.

Activities the paper does not name get a description generated from the goal (``tasks.describe_goal``)
in both modes; ``named`` adds the same instance names. Goals stay strict bddl either way.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from functools import cache
from importlib import resources

from more_agent.errors import unknown_name_error
from more_agent.sim.ambiguity import ambiguous_in, scope_groups, template_scopes, written_scopes
from more_agent.sim.tasks import TaskDefinition, category_phrase, describe_goal
from more_agent.sim.world import World
from more_agent.vocabulary import scope_synset

DESCRIPTION_MODES = ("named", "paper")
"""``named``: the paper's text with what it leaves out and the instances the world makes ambiguous
named (default); ``paper``: the paper's text verbatim (module docstring)."""


def check_description_mode(mode: str) -> None:
    """Raise a UserError naming the valid modes for an unknown one."""
    if mode not in DESCRIPTION_MODES:
        raise unknown_name_error("description mode", mode, list(DESCRIPTION_MODES))


@cache
def description_additions() -> dict[str, str]:
    """Activity -> the goal conditions the paper's description leaves out, with ``$scope`` words."""
    data = json.loads(resources.files("more_agent").joinpath("data", "description_additions.json").read_text())
    return dict(data["additions"])


def description_template(
    definition: TaskDefinition, world: World, scope: Mapping[str, str], mode: str = "named"
) -> str:
    """The description of a task instance with ``$scope`` words (module docstring); ``scope`` maps
    scope names to world object names."""
    check_description_mode(mode)
    paper = definition.paper_description
    text = paper if paper is not None else describe_goal(definition.goal, _scope_word)
    if mode == "paper":
        return text
    if paper is not None:
        text = _sentences(text, description_additions().get(definition.name, ""))
    described = template_scopes(text, definition, world, scope)
    return _sentences(text, naming_sentences(definition, ambiguous_in(world, definition, scope, described, text)))


def naming_sentences(definition: TaskDefinition, ambiguous: list[str]) -> str:
    """Sentences naming the ``ambiguous`` scopes: the goal conditions that write one of them, then
    the range of each quantifier over one of them; '' when there are none."""
    if not ambiguous:
        return ""
    wanted = set(ambiguous)
    conditions = [c for c in definition.goal if wanted & written_scopes(c)]
    out = [f"To be exact: {describe_goal(conditions, _scope_word)}."] if conditions else []
    for group in scope_groups(definition.goal, definition.objects):
        if group.quantifier is not None and wanted & set(group.scopes):
            names = [_scope_word(s) for s in group.scopes]
            listed = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
            out.append(f"The {category_phrase(scope_synset(group.scopes[0]))}(s) meant are {listed}.")
    return " ".join(dict.fromkeys(out))


def _scope_word(scope: str) -> str:
    return f"${scope}"


def _sentences(text: str, more: str) -> str:
    """``text`` followed by ``more`` as a new sentence ('' adds nothing)."""
    if not more:
        return text
    text = text.rstrip()
    return f"{text}{'' if text.endswith(('.', '!', '?')) else '.'} {more}"
