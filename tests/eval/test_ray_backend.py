"""Ray (marker ``ray``: the optional extra more-agent[ray], installed by .ci/run in its own step): same
episodes and metrics as the process pool; LLM limit."""

from __future__ import annotations

from pathlib import Path

import pytest

from more_agent.eval.harness import evaluate
from more_agent.eval.metrics import by_system
from more_agent.eval.store import RunConfig

pytestmark = pytest.mark.ray

REPO = Path(__file__).resolve().parents[2]


def config(fn: str, **kw: object) -> RunConfig:
    base = {"planner": "oracle", "tasks": ["a", "bad", "c", "d"], "seeds": [0, 1], "episode_fn": f"tests.eval.fake_episodes:{fn}"}
    return RunConfig(**{**base, **kw})


@pytest.fixture(scope="module")
def local_ray():
    import ray

    mp = pytest.MonkeyPatch()
    mp.setenv("PYTHONPATH", str(REPO))  # Ray workers import the fake episodes from tests/
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()
    mp.undo()


def test_ray_matches_process_pool(tmp_path: Path, local_ray: None) -> None:
    via_ray = evaluate(config("raising_episode", ray_address="local"), tmp_path / "ray", show_progress=False)
    via_pool = evaluate(config("raising_episode", workers=2), tmp_path / "pool", show_progress=False)

    def outcome(records):
        return sorted(r.model_copy(update={"timings": {}, "traceback": None}).model_dump_json() for r in records)

    assert len(via_ray) == 8 and outcome(via_ray) == outcome(via_pool)
    assert by_system(via_ray) == by_system(via_pool)
    assert sum(r.error is not None for r in via_ray) == 2


def test_ray_limiter_bounds_concurrent_llm_calls(tmp_path: Path, local_ray: None) -> None:
    cfg = config("limited_episode", tasks=["a", "b", "c", "d"], seeds=[0], ray_address="local")
    records = evaluate(cfg, tmp_path / "lim", max_concurrent_llm=1, show_progress=False)
    assert [r.timings["holders"] for r in records] == [1.0] * 4

