"""``scripts/trace_episode.py``: the step-by-step trace that tells which mechanism lost an episode."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import numpy as np
from PIL import Image

from more_agent.planners.grounded import GroundedPlanner
from more_agent.records import EpisodeSpec

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "fixtures" / "tiny_scene.json"


def trace_module() -> ModuleType:
    """The script, imported from its file (scripts/ is no package)."""
    spec = importlib.util.spec_from_file_location("trace_episode", ROOT / "scripts" / "trace_episode.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_trace_prints_each_step_its_reason_and_outcome_and_where_the_robot_truly_is() -> None:
    tracer = trace_module()
    spec = EpisodeSpec(task="store_produce", scene=str(TINY), seed=0, planner="grounded")
    lines: list[str] = []
    world = tracer.truth(spec, lines.append).world
    assert world.objects and ": " in lines[0] and any("ontop" in s or "inside" in s for s in lines[1:])
    told = len(lines)
    record = tracer.trace(spec, lines.append, world)
    steps = [s for s in lines[told:] if s[:3].strip().isdigit()]
    assert len(steps) == record.high_level_steps > 0
    assert all("[" in s and "#" in s for s in steps)  # the true room, and the planner's note
    outcomes = [s for s in lines if s.startswith("    -> ")]
    assert len(outcomes) == len(record.actions)  # one outcome per recorded action
    assert [s.startswith("    -> ok") for s in outcomes] == [a.ok for a in record.actions]
    assert sum(s.startswith("    open: ") for s in lines) == len(steps)
    assert lines[-1].startswith(f"success={record.success} steps={record.high_level_steps}")


def test_the_map_shows_the_robots_own_grid_its_stops_and_which_task_objects_it_saw(tmp_path: Path) -> None:
    tracer = trace_module()
    spec = EpisodeSpec(task="store_produce", scene=str(TINY), seed=0, planner="grounded")
    instance = tracer.truth(spec, lambda _: None)
    planner = GroundedPlanner()
    stops: list[tuple[float, float]] = []
    record = tracer.trace(spec, lambda _: None, planner=planner, stops=stops)
    assert len(stops) == record.high_level_steps  # one stop drawn per step
    tracer.draw_map(planner, instance, stops, tmp_path / "map.png")
    picture = np.asarray(Image.open(tmp_path / "map.png").convert("RGB")).astype(int)
    green = (picture[..., 1] > 120) & (picture[..., 0] < 90) & (picture[..., 2] < 90)
    assert record.success and green.sum() > 20  # the solved episode saw its task objects: green stars
