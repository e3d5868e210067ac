"""A non-privileged planner sees only what a robot sees: it cannot reach the World, the goal checker or
the simulator's internals, neither by import nor through what it holds at run time.

(a) Static: every module under ``more_agent/planners`` but the oracle, and everything it imports
inside ``more_agent`` transitively (lazy and type-only imports included), reaches of ``more_agent.sim``
only geometry and static knowledge (:data:`SIM_ALLOWED`): never the world, the goal, the task
instance, the env or the renderer. (b) Dynamic: after ``reset`` and a few steps on a small world, the
objects a planner holds (its attributes, their contents, closures, bound methods) contain no World,
object of it, goal checker, task instance or env. The walk stops at the robot the runner hands the
planner: that is the boundary, and its public surface is checked on its own.
"""

from __future__ import annotations

import gc
import types
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from more_agent.eval.episode import reset_planner
from more_agent.llm import LLMConfig, make_client
from more_agent.planners.base import Planner
from more_agent.planners.bumble import BUMBLE_CONFIGS, BumblePlanner
from more_agent.planners.grounded import GroundedPlanner
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.planners.oracle import OraclePlanner
from more_agent.robot import Robot
from more_agent.sim.env import MoreAgentEnv, SimRobot
from more_agent.sim.goals import GoalChecker, PrivilegedContext
from more_agent.sim.instantiate import TaskInstance, instantiate_in_scene
from more_agent.sim.objects import WorldObject
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World
from tests.planners.brain import BrainServer, RearrangeBrain
from tests.planners.test_llm_episode import GOAL
from tests.planners.vlm_brain import RearrangeVLM
from tests.test_import_layers import _graph

KITCHEN = Path(__file__).parent / "fixtures" / "tasks_kitchen_scene.json"

ORACLE = "more_agent.planners.oracle"

SIM_ALLOWED = frozenset(
    {
        "more_agent.sim",  # the package: registers the Gymnasium id, imports nothing of ours
        "more_agent.sim.grid",  # raster geometry
        "more_agent.sim.paths",  # shortest paths on a raster
        "more_agent.sim.scene",  # the scene file schema (free-space class names)
        "more_agent.sim.camera",  # the pinhole model
        "more_agent.sim.catalog",  # BEHAVIOR-1K categories, synsets, room inventories
    }
)
"""What of ``more_agent.sim`` a non-privileged planner may import: geometry and static knowledge."""

TRUTH = (World, WorldObject, GoalChecker, TaskInstance, MoreAgentEnv, PrivilegedContext)
"""Objects a non-privileged planner must not reach at run time."""


def forbidden_imports(graph: dict[str, set[str]]) -> list[str]:
    """Import chains from a non-privileged planner module to a module of ``sim`` outside
    :data:`SIM_ALLOWED` or to the oracle, one per module reached."""
    start = [m for m in graph if m.startswith("more_agent.planners") and m != ORACLE]
    parent: dict[str, str] = {}
    seen, queue = set(start), deque(start)
    bad = []
    while queue:
        module = queue.popleft()
        for target in sorted(graph.get(module, ())):
            if target in seen:
                continue
            seen.add(target)
            parent[target] = module
            if target == ORACLE or (target.startswith("more_agent.sim") and target not in SIM_ALLOWED):
                chain = [target]
                while chain[-1] in parent:
                    chain.append(parent[chain[-1]])
                bad.append(" <- ".join(chain))
            else:
                queue.append(target)
    return bad


def test_no_planner_but_the_oracle_imports_ground_truth() -> None:
    bad = forbidden_imports(_graph())
    assert not bad, "\n".join(bad)


def test_the_import_check_finds_a_planner_importing_the_world() -> None:
    graph = {"more_agent.planners.x": {"more_agent.scene_graph"}, "more_agent.scene_graph": {"more_agent.sim.world"}}
    assert forbidden_imports(graph) == ["more_agent.sim.world <- more_agent.scene_graph <- more_agent.planners.x"]
    assert forbidden_imports({ORACLE: {"more_agent.sim.world"}}) == []


def held_objects(root: object, boundary: tuple[type, ...] = (SimRobot,)) -> Iterator[object]:
    """Every object reachable from ``root`` through what it holds (``gc.get_referents``: attributes,
    container contents, closures, bound methods), not through modules, classes or functions' globals,
    and not into instances of ``boundary``."""
    seen = {id(root)}
    queue: deque[object] = deque([root])
    while queue:
        obj = queue.popleft()
        yield obj
        if isinstance(obj, (*boundary, types.ModuleType, type)):
            continue
        if isinstance(obj, types.FunctionType):
            referents: list[Any] = [obj.__closure__, obj.__defaults__, obj.__kwdefaults__]
        else:
            referents = gc.get_referents(obj)
        for ref in referents:
            if ref is not None and id(ref) not in seen:
                seen.add(id(ref))
                queue.append(ref)


def truth_in(root: object) -> list[str]:
    """The types of the ground-truth objects reachable from ``root`` (:func:`held_objects`)."""
    return sorted({type(o).__name__ for o in held_objects(root) if isinstance(o, TRUTH)})


def _kitchen() -> TaskInstance:
    return instantiate_in_scene("putting_shopping_away", load_scene(KITCHEN), seed=0)


def _planners(server: BrainServer, tmp: Path) -> dict[str, Callable[[], Planner]]:
    config = LLMConfig(base_url=server.base_url, api_key="sk-test", timeout_s=2.0, max_retries=0,
                       cache_path=tmp / "cache.sqlite")
    client = make_client("openai:fake-model", config)
    llm: dict[str, Callable[[], Planner]] = {
        name: (lambda c=c: LLMPlanner(c, LLMClients(client, client, "openai:fake-model")))
        for name, c in PLANNER_CONFIGS.items()
    }
    vlm: dict[str, Callable[[], Planner]] = {
        name: (lambda c=c: BumblePlanner(c, client, "openai:fake-model")) for name, c in BUMBLE_CONFIGS.items()
    }
    return {"grounded": GroundedPlanner, **llm, **vlm}


@pytest.mark.parametrize("name", ["grounded", "more", "moma-llm", "moma-llm-sr", "bumble", "bumble-filter"])
def test_no_planner_but_the_oracle_holds_ground_truth(name: str, tmp_path: Path) -> None:
    kitchen = _kitchen()
    with BrainServer(RearrangeVLM(GOAL) if name.startswith("bumble") else RearrangeBrain(GOAL)) as server:
        planner = _planners(server, tmp_path)[name]()
        _, privileged = reset_planner(planner, kitchen, GoalChecker(kitchen))
        assert privileged is None
        for _ in range(3):
            planner.observe()
            planner.execute(planner.decide())
    assert truth_in(planner) == []
    assert truth_in(planner.step_trace()) == []


def test_the_robot_gives_nothing_of_the_world() -> None:
    """The boundary itself: what the Robot protocol hands out, and the robot's public attributes."""
    kitchen = _kitchen()
    robot = SimRobot(kitchen.world, labels=kitchen.labels)
    surface = [getattr(robot, name) for name in ("class_names", "pose", "held", "trajectory", "low_level_steps")]
    surface += [robot.sense(), robot.act("navigate_to", "fridge_0"), robot.reach_distance("fridge A")]
    surface += [value for name, value in vars(robot).items() if not name.startswith("_")]
    assert isinstance(robot, SimRobot) and set(Robot.__dict__) >= {"sense", "act", "pose"}
    assert truth_in(surface) == []


def test_the_walk_finds_the_world_the_oracle_is_granted() -> None:
    """The check can fail: the oracle holds the world, and a world hidden in a closure or a list is found."""
    kitchen = _kitchen()
    oracle = OraclePlanner()
    reset_planner(oracle, kitchen, GoalChecker(kitchen))
    assert "World" in truth_in(oracle) and "GoalChecker" in truth_in(oracle)
    world = kitchen.world
    hidden = [lambda: world]
    assert "World" in truth_in(hidden)
