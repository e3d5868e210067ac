"""BUMBLE's memories (Shah et al. 2024, arXiv 2410.06237): the episode's steps with their images, and failures of earlier trials.

- **Short-term visual memory**: BUMBLE sends, with every step decision, the steps of the episode so
  far, each as one message carrying the annotated image the VLM saw at that step, the subtask and
  skill it chose, whether the skill succeeded and the feedback of a failure, answered by a short
  verdict on that choice. Here the images are the step's marked current view, downscaled to
  :data:`HISTORY_IMAGE_PX` pixels a side, on the last :data:`HISTORY_IMAGES` steps (BUMBLE's code sends
  one per earlier step, bounded by its episode length; our episodes run longer); older steps keep
  their text.
- **Long-term memory** (BUMBLE's ``--add_past``): summaries of failed skill executions of earlier
  trials, put before the episode's history. BUMBLE keeps failed selections only; so does this memory.
  The planner is given them (``EpisodeContext.past_failures``) and leaves its own in its record
  (``failure_summaries``), so the trials' records are the memory: ``more-agent eval --trials N
  --long-term-memory`` gives trial k those of trials 0 .. k-1 of its world. Across separate
  ``more-agent run`` invocations a :class:`FailureStore` carries them instead: a JSON Lines file (one
  ``{"task", "summary"}`` per line, the task's name) read before the episode and appended to after it
  (``--bumble-memory PATH``). Without either there is no long-term memory, as BUMBLE without ``--add_past``.

Written from the paper and the public code's behaviour, not copied.
"""

from __future__ import annotations

import io
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from more_agent.errors import UserError
from more_agent.llm.completion import ChatMessage
from more_agent.llm.images import image_part, text_part
from more_agent.safe_files import append_text, read_bounded

HISTORY_IMAGES = 8
"""Most earlier steps sent with their image; older steps are sent as text."""

HISTORY_IMAGE_PX = 128
"""Side in pixels of an earlier step's image (the current view keeps its full size)."""

LONG_TERM_SUMMARIES = 5
"""Most failure summaries of earlier trials put into one request (the most recent ones)."""

MAX_MEMORY_BYTES = 4_000_000
"""Largest long-term memory file read."""

SHORT_TERM_INTRO = (
    "The steps of this episode so far follow, each with the annotated view you saw then, the subtask and skill "
    "you chose, and whether the skill succeeded. Pay attention to the failures and their feedback, and do not "
    "repeat an error."
)
LONG_TERM_INTRO = (
    "Summaries of failures in earlier trials of this task (not of this episode). Avoid repeating these errors:"
)
RIGHT = "The choice was appropriate for the subtask."
WRONG = "I made an error in this choice."


@dataclass(frozen=True)
class PastStep:
    """One earlier step of the episode as the short-term memory shows it."""

    subtask: str
    skill: str
    ok: bool
    feedback: str
    png: bytes | None
    """The step's annotated view, downscaled (None when the step had no view)."""

    def text(self, number: int) -> str:
        """'Step 3 - subtask: open fridge A; skill: go_to_and_open; success: no; feedback: ...'."""
        outcome = "yes" if self.ok else f"no; feedback: {self.feedback}"
        return f"Step {number} - subtask: {self.subtask or 'none'}; skill: {self.skill}; success: {outcome}"


def downscaled_png(png: bytes, side: int = HISTORY_IMAGE_PX) -> bytes:
    """``png`` resized to ``side`` pixels on its longer side (never enlarged)."""
    from PIL import Image

    image = Image.open(io.BytesIO(png)).convert("RGB")
    image.thumbnail((side, side))
    out = io.BytesIO()
    image.save(out, format="PNG", compress_level=1)
    return out.getvalue()


def short_term_messages(steps: Sequence[PastStep], max_images: int = HISTORY_IMAGES) -> list[ChatMessage]:
    """The episode's steps as BUMBLE sends them: an introduction, then per step a user message (its
    text, and its image for the last ``max_images`` steps) and the assistant's verdict on it."""
    if not steps:
        return []
    first_image = len(steps) - max_images
    messages = [ChatMessage(role="user", content=SHORT_TERM_INTRO)]
    for k, step in enumerate(steps):
        parts = [text_part(step.text(k + 1))]
        if step.png is not None and k >= first_image:
            parts.append(image_part(step.png))
        messages += [
            ChatMessage(role="user", content=parts),
            ChatMessage(role="assistant", content=RIGHT if step.ok else WRONG),
        ]
    return messages


def long_term_message(summaries: Sequence[str], limit: int = LONG_TERM_SUMMARIES) -> list[ChatMessage]:
    """The long-term memory as one user message (the last ``limit`` summaries), or none."""
    if not summaries:
        return []
    lines = [f"Summary {k}: {s}" for k, s in enumerate(summaries[-limit:], start=1)]
    return [ChatMessage(role="user", content="\n".join([LONG_TERM_INTRO, *lines]))]


def failure_summary(step: PastStep) -> str:
    """What a failed step leaves in the long-term memory: the choice and why it failed."""
    return f"choosing {step.skill} for the subtask '{step.subtask}' failed: {step.feedback}"


class FailureStore:
    """The long-term memory file of ``more-agent run --bumble-memory``: failure summaries per task (module docstring)."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def summaries(self, task: str) -> list[str]:
        """The summaries stored for ``task``, oldest first; none when the file does not exist yet.
        Raises UserError naming the file and line of an entry that is not ``{"task", "summary"}``."""
        if not self.path.exists():
            return []
        text = read_bounded(self.path, what="BUMBLE long-term memory", max_bytes=MAX_MEMORY_BYTES)
        out = []
        for number, line in enumerate(text.splitlines(), start=1):
            if not line.strip():
                continue
            try:
                entry = json.loads(line)
                entry_task, summary = entry["task"], entry["summary"]
            except (ValueError, KeyError, TypeError):
                raise UserError(
                    f'{self.path}:{number}: not a long-term memory entry {{"task": ..., "summary": ...}}'
                ) from None
            if entry_task == task and isinstance(summary, str):
                out.append(summary)
        return out

    def add(self, task: str, summaries: Sequence[str]) -> None:
        """Append an episode's summaries in one write (the file and its folder are created when missing)."""
        if not summaries:
            return
        self.path.parent.mkdir(parents=True, exist_ok=True)
        append_text(self.path, "".join(json.dumps({"task": task, "summary": s}) + "\n" for s in summaries))
