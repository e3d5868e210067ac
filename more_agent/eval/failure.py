"""Why an episode failed: one cause per unsuccessful episode, from its own trace and the world's ground truth.

:func:`classify_failure` runs after the episode, for every planner, on the finished record (its
actions and feedback, error, goal conditions, observed task objects) and the final world. Causes
are checked in the order of :data:`CAUSE_ORDER`; the first that applies wins (docs/evaluation.md
defines each). Counts per cause and system are pure functions of records (:func:`cause_counts`).
Everything it reads is typed: the actions' :class:`~more_agent.records.FailureReason`, the episode's
termination and error kind; no feedback or error text is parsed.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence

from more_agent.eval.termination import describe
from more_agent.records import (
    REACH_FAILURES,
    ActionRecord,
    EpisodeRecord,
    Failure,
    FailureCause,
    FailureReason,
    GoalCondition,
)
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.predicates import PREDICATES
from more_agent.sim.world import World
from more_agent.skills import SKILLS

CAUSE_ORDER: tuple[FailureCause, ...] = (
    "llm_error",
    "other",
    "unsatisfiable",
    "done_not_called",
    "wrong_instance",
    "misperceived",
    "never_observed",
    "invalid_llm_answers",
    "unreachable",
    "subpolicy_failure",
    "done_early",
    "step_limit",
)
"""Causes in the order they are tested; 'other' here means a system error other than the LLM's (code raised,
bad input: ``record.error``) or an episode that never ran."""

INVALID_SHARE = 0.5
"""An episode whose share of invalid actions reaches this failed on the LLM's answers."""

MANIPULATING = frozenset(s.name for s in SKILLS if s.changes_world)
"""The skills that act on an object (grasp, place, open, close)."""

OPENING = frozenset({"go_to_and_open", "go_to_and_close"})
"""Manipulating skills that also serve a search: opening a container looks inside it."""


def is_reach_failure(action: ActionRecord) -> bool:
    """Whether a failed action failed on the way to its target (no path, blocked), not at it."""
    return not action.ok and action.reason in REACH_FAILURES


def classify_failure(
    record: EpisodeRecord,
    world: World | None,
    labels: InstanceLabels | None,
    goal_objects: Iterable[str] = (),
    satisfiable: bool = True,
) -> Failure | None:
    """The failure of a finished episode (None for a success); see the module docstring. ``goal_objects``: the
    objects the goal may use (``GoalChecker.objects``: any ground option's, any quantifier's range), none of
    them a wrong instance. ``satisfiable``: whether any state meets the goal (``GoalChecker.satisfiable``)."""
    if record.success:
        return None
    if record.error_kind == "llm":
        return Failure(cause="llm_error", detail=record.error or "")
    if record.error is not None or world is None or labels is None:
        return Failure(cause="other", detail=record.error or "the episode did not run")
    if not satisfiable:
        return Failure(cause="unsatisfiable", detail="no state meets the goal, whatever the robot does (docs/tasks.md)")
    ended = describe(record.termination) if record.termination not in (None, "done") else ""
    if record.all_goals_met:
        return Failure(cause="done_not_called", detail=ended or "every goal condition held; done() never called")
    unmet = [c for c in record.goal_conditions if not c.satisfied]
    achievable = [c for c in unmet if is_modelled(c)]  # seeing or reaching the objects of the others changes nothing
    needed = sorted({o for c in achievable for o in c.objects if o in world.objects and world.get(o).kind != "floor"})
    called = {o: labels.label(o) or o for o in needed}
    goal_objects = {o for c in record.goal_conditions for o in c.objects} | set(goal_objects)
    opened = {o for c in achievable if predicate_of(c) == "open" for o in c.objects}
    wrong = _wrong_instances(record.actions, needed, goal_objects, opened, world, labels)
    if wrong:
        return Failure(cause="wrong_instance", detail=wrong)
    misperceived = _misperceived(record, needed, world, labels)
    if misperceived:
        return Failure(cause="misperceived", detail=misperceived)
    unseen = [o for o in needed if o not in set(record.observed_objects)]
    if unseen:
        return Failure(cause="never_observed", detail="never observed " + ", ".join(called[o] for o in unseen))
    invalid = sum(a.reason is FailureReason.INVALID_ANSWER for a in record.actions)
    if record.actions and invalid / len(record.actions) >= INVALID_SHARE:
        return Failure(
            cause="invalid_llm_answers", detail=f"{invalid} of {len(record.actions)} actions were invalid answers"
        )
    refs = {ref for o in needed for ref in (o, called[o])}  # the oracle names world objects, the others labels
    on_needed = [a for a in record.actions if not a.ok and refs & set(a.arguments)]
    reach = [a for a in on_needed if is_reach_failure(a)]
    if reach:
        return Failure(
            cause="unreachable", detail=f"{reach[-1].name}({', '.join(reach[-1].arguments)}): {reach[-1].feedback}"
        )
    if on_needed:
        last = on_needed[-1]
        return Failure(cause="subpolicy_failure", detail=f"{last.name}({', '.join(last.arguments)}): {last.feedback}")
    first_unmet = unmet[0].text if unmet else ""
    if record.done_called:
        return Failure(cause="done_early", detail=record.gave_up or f"done() with {first_unmet} unmet")
    return Failure(cause="step_limit", detail=f"{ended or 'step limit'}; {first_unmet} unmet")


def is_modelled(condition: GoalCondition) -> bool:
    """Whether the world models the predicate of a goal condition; no robot meets one it does not model
    (``cooked``, ``covered``, ...: docs/tasks.md)."""
    return predicate_of(condition) in PREDICATES


def predicate_of(condition: GoalCondition) -> str:
    """The predicate of a goal condition's bddl literal, ``(not (p ...))`` or ``(p ...)``."""
    words = condition.text.replace("(", " ").split()
    return words[1] if words[:1] == ["not"] and len(words) > 1 else words[0] if words else ""


def _wrong_instances(
    actions: Sequence[ActionRecord],
    needed: Sequence[str],
    goal_objects: set[str],
    opened: set[str],
    world: World,
    labels: InstanceLabels,
) -> str:
    """'acted on cup B; the goal needs cup A'-style detail when the robot manipulated another instance of a
    needed object's category, one the goal does not name at all, but never the needed one; '' otherwise.
    Opening or closing counts only for the objects an unmet condition wants open or closed (``opened``):
    otherwise it is a search looking inside (car B opened for the picnic food while car A is not found)."""
    goal_refs = goal_objects | {labels.label(o) for o in goal_objects if o in world.objects}
    acted = [a for a in actions if a.ok and a.name in MANIPULATING and a.arguments]
    every = {a.arguments[-1] for a in acted}
    used = {a.arguments[-1] for a in acted if a.name not in OPENING}
    for name in needed:
        obj = world.get(name)
        touched = every if name in opened else used
        if labels.label(name) in touched or name in touched:
            continue
        others = sorted(
            t
            for t in touched - goal_refs
            if (o := world.objects.get(t) or world.objects.get(labels.find(t) or "")) is not None
            and o.category == obj.category
        )
        if others:
            return f"acted on {', '.join(others)}; the goal needs {labels.label(name) or name + ' (never observed)'}"
    return ""


def _misperceived(record: EpisodeRecord, needed: Sequence[str], world: World, labels: InstanceLabels) -> str:
    """'apple A: seen as pear C'-style detail when noisy perception hid a needed object that was in view
    (never perceived as itself), or the robot manipulated an object under a label of another category;
    '' otherwise (always under ground-truth perception)."""
    hidden = [f"{labels.label(o) or o}: {record.misperceived[o]}" for o in needed if o in record.misperceived]
    if hidden:
        return "; ".join(hidden)
    for a in record.actions:
        label = a.arguments[-1] if a.ok and a.name in MANIPULATING and a.arguments else ""
        real = record.perception_aliases.get(label)
        if real in world.objects and not label.startswith(world.get(real).category + " "):
            return f"acted on {label}, which is {labels.label(real) or real}"
    return ""


def cause_counts(records: Iterable[EpisodeRecord]) -> Counter[FailureCause]:
    """Number of episodes per failure cause (successes are not counted)."""
    return Counter(r.failure.cause for r in records if r.failure is not None)
