"""Perception errors as array operations: each kind does what docs/sensors.md says, and only that."""

from __future__ import annotations

import numpy as np
import pytest

from more_agent.errors import UserError
from more_agent.perception.noise import (
    DepthNoise,
    InstanceTables,
    drift_step,
    drifted_pose,
    miss_probability,
    perturb_instances,
)
from more_agent.perception.taxonomy import relatives, sibling_category
from more_agent.perception_spec import DEFAULTS, ERROR_KINDS, PerceptionSpec, parse_perception


def test_spec_text_round_trips_and_names_only_the_changed_rates() -> None:
    assert parse_perception("gt").text() == "gt" and not parse_perception("gt").noisy
    assert parse_perception("noisy").text() == "noisy" and parse_perception("noisy").noisy
    spec = parse_perception(" noisy: depth=0 , miss=0.3")
    assert spec.text() == "noisy:miss=0.3,depth=0" and spec.depth == 0 and spec.confusion == DEFAULTS["confusion"]
    assert parse_perception(spec.text()) == spec
    only = PerceptionSpec().only("drift")
    assert only.drift == DEFAULTS["drift"] and all(getattr(only, k) == 0 for k in ERROR_KINDS if k != "drift")
    assert not parse_perception("noisy:" + ",".join(f"{k}=0" for k in ERROR_KINDS)).noisy


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("noisy:mis=0.1", "valid keys: confusion, miss, fragment"),
        ("noisy:miss=2", "less than or equal to 1"),
        ("noisy:miss=lots", "a rate is a number"),
        ("noisy:miss", "a rate is a number"),
        ("fuzzy", "'gt' or 'noisy"),
        ("gt:miss=0.1", "gt takes no settings"),
    ],
)
def test_bad_perception_values_give_one_clear_error(text: str, says: str) -> None:
    with pytest.raises(UserError, match=says):
        parse_perception(text)


def test_depth_error_grows_with_range_and_keeps_invalid_pixels() -> None:
    depth = np.concatenate([np.full((100, 100), 1.0), np.full((100, 100), 4.0)]).astype(np.float32)
    depth[0, 0] = np.nan
    out = DepthNoise(np.random.default_rng(0)).apply(depth, 0.01)
    near, far = (out[:100] - 1.0)[1:], out[100:] - 4.0
    assert np.isnan(out[0, 0]) and out.dtype == np.float32
    assert np.nanstd(near) == pytest.approx(0.01, rel=0.05) and np.std(far) == pytest.approx(0.04, rel=0.05)


def test_misses_grow_with_range_occlusion_and_smallness() -> None:
    def p(r: float = 2.5, v: float = 0.5, s: float = 0.3) -> float:
        return float(miss_probability(0.2, np.array([r]), np.array([v]), np.array([s]))[0])

    assert p() == pytest.approx(0.2)
    assert p(r=1.0) < p() < p(r=4.0)
    assert p(v=1.0) < p() < p(v=0.1)
    assert p(s=1.0) < p() < p(s=0.1)
    assert p(r=5.0, v=0.0, s=0.01) == pytest.approx(0.95)  # never certain


def scene() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Depth, semantic, instance frames: instance 1 (class 5) and its close neighbour 2 (class 6) at 2 m,
    a door (instance 3, class 7) at 3 m, floor (class 1, instance 0) elsewhere."""
    depth = np.full((64, 64), 2.0, dtype=np.float32)
    semantic = np.ones((64, 64), dtype=np.int32)
    instance = np.zeros((64, 64), dtype=np.int32)
    instance[10:30, 10:30], semantic[10:30, 10:30] = 1, 5
    instance[10:30, 32:40], semantic[10:30, 32:40] = 2, 6
    instance[40:60, 0:20], semantic[40:60, 0:20], depth[40:60, 0:20] = 3, 7, 3.0
    return depth, semantic, instance


def tables(**draws: list[bool] | list[int]) -> InstanceTables:
    n = 4
    own = np.array([0, 5, 6, 7])
    seen = np.array(draws.get("seen_class", own))
    return InstanceTables(
        size_m=np.array([0.0, 0.4, 0.2, 1.0]),
        eligible=np.array([False, True, True, False]),  # the door is structure
        seen_class=seen,
        confused=seen != own,
        fragment=np.array(draws.get("fragment", [False] * n)),
        merge=np.array(draws.get("merge", [False] * n)),
    )


def test_misses_blank_whole_instances_small_ones_more_and_never_doors() -> None:
    depth, semantic, instance = scene()
    rng, missed = np.random.default_rng(0), np.zeros(4)
    for _ in range(300):
        found = perturb_instances(depth, semantic, instance, 32.0, tables(), 0.5, rng)
        sem, inst = found.semantic, found.instance
        assert all(found.kept[i] == (inst == i).any() for i in (1, 2, 3))
        for i in (1, 2, 3):
            gone = inst[instance == i] == 0
            assert gone.all() or not gone.any()  # a detection is missed whole
            assert (sem[instance == i][gone] == 0).all()
            missed[i] += gone.all()
    assert missed[3] == 0 and 0 < missed[1] < missed[2] < 300  # the smaller item is missed more


def test_no_error_drawn_leaves_the_frames_unchanged() -> None:
    depth, semantic, instance = scene()
    found = perturb_instances(depth, semantic, instance, 32.0, tables(), 0.0, np.random.default_rng(0))
    assert (found.semantic == semantic).all() and (found.instance == instance).all()
    assert found.kept[1:].all() and found.in_view.all()


def test_confusion_fragmentation_and_merging() -> None:
    depth, semantic, instance = scene()
    t = tables(seen_class=[0, 6, 6, 7], fragment=[False, True, False, False])
    found = perturb_instances(depth, semantic, instance, 32.0, t, 0.0, np.random.default_rng(0))
    sem, inst = found.semantic, found.instance
    assert (sem[instance == 1] == 6).all()  # seen as its sibling's class, same instance ...
    assert set(np.unique(inst[instance == 1])) == {1, 1 + 4}  # ... in two pieces, split at its middle
    left, right = np.nonzero(inst == 1)[1], np.nonzero(inst == 1 + 4)[1]
    assert left.max() < right.min() and abs(len(left) - len(right)) <= 0.2 * len(left)  # split near its middle column
    found = perturb_instances(
        depth, semantic, instance, 32.0, tables(merge=[False, False, True, False]), 0.0, np.random.default_rng(0)
    )
    sem, inst = found.semantic, found.instance
    assert not found.kept[2] and found.in_view[2]
    assert (inst[instance == 2] == 1).all() and (sem[instance == 2] == 5).all()  # merged into its close neighbour


def test_far_instances_do_not_merge() -> None:
    depth, semantic, instance = scene()
    depth[instance == 2] = 4.0
    found = perturb_instances(
        depth, semantic, instance, 32.0, tables(merge=[False, False, True, False]), 0.0, np.random.default_rng(0)
    )
    assert (found.instance[instance == 2] == 2).all()


def test_same_generator_same_errors() -> None:
    depth, semantic, instance = scene()
    runs = [
        perturb_instances(depth, semantic, instance, 32.0, tables(), 0.5, np.random.default_rng(7)) for _ in range(2)
    ]
    assert (runs[0].instance == runs[1].instance).all() and (runs[0].semantic == runs[1].semantic).all()


def test_drift_accumulates_with_distance_and_turns_about_the_robot() -> None:
    assert (drift_step(np.eye(3), (1.0, 2.0), 5.0, 0.0, np.random.default_rng(0)) == np.eye(3)).all()
    rng = np.random.default_rng(0)
    errors = {d: [] for d in (1.0, 16.0)}
    for d in errors:
        for _ in range(400):
            T = drift_step(np.eye(3), (3.0, 4.0), d, 0.02, rng)
            errors[d].append(np.linalg.norm(T @ np.array([3.0, 4.0, 1.0]) - [3.0, 4.0, 1.0]))
    assert np.mean(errors[16.0]) == pytest.approx(4 * np.mean(errors[1.0]), rel=0.2)  # sqrt(distance)
    T = drift_step(np.eye(3), (3.0, 4.0), 16.0, 0.02, np.random.default_rng(1))
    pose = np.eye(4)
    pose[:3, 3] = [3.0, 4.0, 1.2]
    moved = drifted_pose(T, pose)
    assert moved[2, 3] == 1.2 and np.allclose(moved[:2, 3], T[:2, :2] @ [3.0, 4.0] + T[:2, 2])


def test_confused_categories_are_taxonomy_relatives_in_the_vocabulary() -> None:
    assert "pear" in relatives("apple")[0] and "apple" not in relatives("apple")[0]
    rng = np.random.default_rng(0)
    assert sibling_category("apple", ["pear", "fridge"], rng) == "pear"
    assert sibling_category("apple", ["fridge"], rng) is None
