"""How an episode's start is chosen: the names ``--start`` takes, checked before any world is built.

Apart from ``sim.start`` (which draws the start and imports the navigation grids and scipy) so that a command
checks its arguments without loading the simulator.
"""

from __future__ import annotations

from more_agent.errors import UserError

START_MODES = ("random", "random-area", "task-room")
"""``random`` (default): a reachable room drawn uniformly, then a uniform pose in it; ``random-area``:
a pose uniform over all reachable free space, so large rooms (stores, gardens) take most starts;
``task-room``: a free spot in the room of the task's ``(ontop agent floor)`` literal."""


def check_start(start: str) -> None:
    """Raise a UserError naming the valid values when ``start`` is not one of ``START_MODES``."""
    if start not in START_MODES:
        raise UserError(f"unknown start {start!r}; use --start with one of: {', '.join(START_MODES)}")
