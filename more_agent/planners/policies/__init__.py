"""Subpolicies of the LLM planners: the embodied robot (``embodiment``), paths on the agent's map
(``navigation``) and the skills explore / navigate / go_to_and_<verb> with their dispatch from the
skill table (``skills``)."""

from more_agent.planners.policies.embodiment import Embodiment, PolicyConfig
from more_agent.planners.policies.navigation import agent_nav_grid, object_goal, path_to_nearest
from more_agent.planners.policies.skills import (
    SUBPOLICIES,
    Area,
    explore,
    explore_frontiers,
    go_to_and,
    navigate,
    pick_target,
    run_skill,
)

__all__ = [
    "SUBPOLICIES",
    "Area",
    "Embodiment",
    "PolicyConfig",
    "agent_nav_grid",
    "explore",
    "explore_frontiers",
    "go_to_and",
    "navigate",
    "object_goal",
    "path_to_nearest",
    "pick_target",
    "run_skill",
]
