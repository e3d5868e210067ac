"""Public entry to scenes: the 51 BEHAVIOR-1K scene names, generated plans, user scene files."""

from __future__ import annotations

from functools import lru_cache

from more_agent.errors import unknown_name_error
from more_agent.sim import catalog
from more_agent.sim.floorplan import generate_floorplan, scene_rng
from more_agent.sim.scene import Scene, load_scene

__all__ = ["scene_names", "get_scene", "load_scene"]


def scene_names() -> list[str]:
    """The 51 BEHAVIOR-1K scene names, sorted."""
    return catalog.scene_names()


@lru_cache(maxsize=64)
def get_scene(name: str, seed: int = 0) -> Scene:
    """The floor plan of a BEHAVIOR-1K scene for a seed (deterministic), or a scene file if ``name`` ends in .json.

    Unknown names raise a UserError listing the closest ones; a bad file raises SceneError naming the field.
    """
    if name.endswith(".json"):
        return load_scene(name)
    if name not in scene_names():
        raise unknown_name_error("scene", name, scene_names())
    return generate_floorplan(name, catalog.scene_rooms(name), rng=scene_rng(name, seed), seed=seed)
