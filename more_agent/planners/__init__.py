"""Planners: the protocol and registry (``base``), the privileged oracle, the LLM planners and ``grounded``."""

from more_agent.planners.base import (
    DONE,
    EpisodeContext,
    HighLevelAction,
    Planner,
    default_planner,
    make_planner,
    planner_names,
    register_planner,
)

__all__ = [
    "DONE",
    "EpisodeContext",
    "HighLevelAction",
    "Planner",
    "default_planner",
    "make_planner",
    "planner_names",
    "register_planner",
]
