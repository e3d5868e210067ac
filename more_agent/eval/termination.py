"""When an episode ends (paper Sec. III-D), and how its end reads in words.

The runner (:mod:`more_agent.eval.episode`) applies the limits and records a typed
:data:`~more_agent.records.Termination`; the failure taxonomy and the displays word it through
:func:`describe`, so the phrase lives here only.
"""

from __future__ import annotations

from more_agent.records import Termination

MAX_HIGH_LEVEL_STEPS = 50
"""An episode ends after this many high-level steps (paper Sec. III-D)."""

STEPS_AFTER_GOAL = 5
"""An episode ends when the planner acts more than this many steps after all goal conditions hold without done()."""

_ENDINGS: dict[Termination, str] = {
    "done": "the planner called done()",
    "step_limit": f"step limit of {MAX_HIGH_LEVEL_STEPS} high-level steps reached",
    "steps_after_goal": f"acted for more than {STEPS_AFTER_GOAL} steps after all goal conditions held, without done()",
}


def describe(termination: Termination) -> str:
    """How an episode's end reads: 'step limit of 50 high-level steps reached'."""
    return _ENDINGS[termination]
