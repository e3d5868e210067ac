"""``timeline.jsonl``: what the episode runner knows after each high-level step, for the episode viewer.

One line per step, for every planner (the oracle included): the goal conditions and whether each
held after the step (evaluation-only knowledge the planner never sees), how far the robot's path and
low-level step count had grown, the action's targets by instance label, and how many sensor frames had been written (``--save-frames``), so
the viewer can cut the episode's path and frames into steps. Planner-specific detail (scene texts,
LLM exchanges) stays in the planner's own ``steps.jsonl``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from more_agent.records import EpisodeRecord

if TYPE_CHECKING:
    from more_agent.sim.goals import GoalStatus

TIMELINE_FILE = "timeline.jsonl"


class TimelineWriter:
    """Appends one line per step to ``out_dir/timeline.jsonl`` (truncated when created)."""

    def __init__(self, out_dir: Path) -> None:
        from more_agent.viz.frames import FRAMES_DIR

        out_dir.mkdir(parents=True, exist_ok=True)
        self.path = out_dir / TIMELINE_FILE
        self.frames_dir = out_dir / FRAMES_DIR
        self.path.write_text("", encoding="utf-8")

    def append(self, record: EpisodeRecord, status: GoalStatus, targets: list[str]) -> None:
        """The line of the step just recorded in ``record`` (its last action); ``targets`` are the
        action's arguments as instance labels ('fridge A'), as the robot's map names objects."""
        from more_agent.viz.frames import frames_written

        line = {
            "step": record.actions[-1].step,
            "path_len": len(record.trajectory),
            "low_level_steps": record.low_level_steps,
            "frames": frames_written(self.frames_dir),
            "goals": [[c.text, c.satisfied] for c in status.conditions],
            "progress": round(status.progress, 4),
            "targets": targets,
        }
        with self.path.open("a", encoding="utf-8") as f:
            f.write(json.dumps(line) + "\n")
