"""The action history the LLM and VLM planners keep: one record per executed action, and the feedback line."""

from __future__ import annotations

from more_agent.llm.limits import MAX_FEEDBACK_CHARS, clip
from more_agent.planners.base import Step
from more_agent.records import ActionRecord
from more_agent.robot import ActionResult


def append_action(history: list[ActionRecord], action: Step, result: ActionResult) -> str:
    """Append the executed ``action`` and its outcome to ``history``; returns the feedback line the
    next prompt shows (``skill: success|failure; reason``). The feedback is clipped: it reaches every
    later prompt through the history."""
    feedback = clip(result.feedback, MAX_FEEDBACK_CHARS)
    history.append(
        ActionRecord(
            step=len(history),
            name=action.name,
            arguments=list(action.arguments),
            ok=result.ok,
            reason=result.reason,
            feedback=feedback,
        )
    )
    return f"{action.name}: {'success' if result.ok else 'failure'}; {feedback}"
