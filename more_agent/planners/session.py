"""What a planner that maps as it goes keeps of its episode: the body it drives (set by ``reset()``) and
the step's scene graph (set by ``observe()``), read through the one state guard ``base.needed``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from more_agent.planners.base import needed

if TYPE_CHECKING:
    from more_agent.planners.policies import Embodiment
    from more_agent.scene_graph import SceneGraph


class MappingSession:
    """Base of the LLM and VLM planners: ``body`` and ``graph``, and their guarded readers."""

    body: Embodiment | None
    graph: SceneGraph | None

    def _body(self) -> Embodiment:
        return needed(self.body, "reset()")

    def _graph(self) -> SceneGraph:
        return needed(self.graph, "observe()")
