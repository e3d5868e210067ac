"""Planners: the protocol and registry (``base``), the privileged oracle, the LLM planners and ``grounded``."""

from more_agent.planners.base import (
    DONE,
    EpisodeContext,
    Planner,
    Step,
    default_planner,
    make_planner,
    planner_names,
    register_planner,
)

__all__ = [
    "DONE",
    "EpisodeContext",
    "Planner",
    "Step",
    "default_planner",
    "make_planner",
    "planner_names",
    "register_planner",
]
