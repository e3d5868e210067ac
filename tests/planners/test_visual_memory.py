"""The frame buffer, frame selection and the VLM answer parsers of the BUMBLE planners."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from more_agent.llm.errors import InvalidAnswer
from more_agent.planners.visual_memory import (
    MemoryConfig,
    VisualMemory,
    covering_frames,
    memory_frame,
    shows_points,
    spread,
)
from more_agent.planners.vlm_prompts import parse_choice, parse_step, parse_verdict
from more_agent.sensing_spec import SensingCadence
from more_agent.sim.camera import Camera
from more_agent.sim.render import Frame


def _frame(x: float, y: float, yaw: float, ids: tuple[int, ...] = (), depth_m: float = np.nan) -> Frame:
    cam = Camera()
    instance = np.zeros((cam.height, cam.width), dtype=np.int32)
    for k, i in enumerate(ids):
        instance[10 * k:10 * k + 5, :5] = i
    return Frame(rgb=np.full((cam.height, cam.width, 3), 7, dtype=np.uint8),
                 depth=np.full((cam.height, cam.width), depth_m, dtype=np.float32), semantic=instance.copy(),
                 instance=instance, K=cam.intrinsics(), T_world_cam=cam.pose(x, y, yaw))


def test_buffer_keeps_a_frame_per_half_metre_or_thirty_degrees() -> None:
    memory = VisualMemory(MemoryConfig())
    poses = [(0, 0, 0), (0.2, 0, 0), (0.45, 0, 0), (0.55, 0, 0), (0.55, 0, math.radians(20)), (0.55, 0, math.radians(35))]
    kept = [memory.offer(_frame(*p)) is not None for p in poses]
    assert kept == [True, False, False, True, False, True]
    assert [f.index for f in memory.frames] == [0, 1, 2] and memory.since(1) == memory.frames[1:]


def test_buffer_keeps_frames_by_a_sensing_cadence() -> None:
    """The buffer keeps frames by a ``SensingCadence``: BUMBLE's 0.5 m or 30 deg by default, or the one set."""
    assert MemoryConfig().keep == SensingCadence(distance_m=0.5, angle_deg=30.0)
    memory = VisualMemory(MemoryConfig(keep=SensingCadence(distance_m=1.0, angle_deg=45.0)))
    poses = [(0, 0, 0), (0.6, 0, 0), (1.0, 0, 0), (1.0, 0, math.radians(40)), (1.0, 0, math.radians(46))]
    assert [memory.offer(_frame(*p)) is not None for p in poses] == [True, False, True, False, True]


def test_kept_frame_round_trips_its_images() -> None:
    frame = _frame(1, 2, 0.3, ids=(4, 9))
    kept = memory_frame(frame, index=0, step=3)
    assert kept.instance_ids == {4, 9} and kept.step == 3
    assert np.array_equal(kept.rgb(), frame.rgb) and np.array_equal(kept.instance(), frame.instance)
    assert kept.pose == pytest.approx((1, 2, 0.3))
    assert kept.png.startswith(b"\x89PNG")


def test_a_frame_counts_its_instance_pixels_once_and_a_replaced_frame_its_own() -> None:
    """``Frame.instance_pixels`` is the image's bincount, read-only (several consumers share it); a frame made
    from it with another instance image counts that image."""
    frame = _frame(0, 0, 0, ids=(4, 9))
    assert frame.instance_pixels is frame.instance_pixels and not frame.instance_pixels.flags.writeable
    assert frame.instance_pixels.tolist() == np.bincount(frame.instance.ravel()).tolist()
    assert np.flatnonzero(replace(frame, instance=np.full_like(frame.instance, 2)).instance_pixels).tolist() == [2]


def test_points_seen_are_in_view_in_front_and_not_hidden() -> None:
    open_view = memory_frame(_frame(0, 0, 0), index=0, step=0)  # saw nothing within range: nothing hides
    ahead, behind, aside = (2.0, 0.0), (-2.0, 0.0), (0.0, 3.0)
    assert shows_points(open_view, np.array([ahead, behind, aside])).tolist() == [True, False, False]
    walled = memory_frame(_frame(0, 0, 0, depth_m=0.5), index=1, step=0)  # a wall half a metre ahead
    assert shows_points(walled, np.array([ahead])).tolist() == [False]


def test_covering_frames_pick_frames_showing_the_most_within_the_bound() -> None:
    frames = [memory_frame(_frame(i, 0, 0, ids), index=i, step=0) for i, ids in enumerate([(1, 2), (2, 3, 4), (1,), (5,)])]
    assert [f.index for f in covering_frames(frames, {1, 2, 3, 4}, 8)] == [1, 2]  # most new first; ties: most recent
    assert [f.index for f in covering_frames(frames, {1, 2, 3, 4, 5}, 2)] == [1, 3]  # bounded
    assert covering_frames(frames, {7}, 8) == []
    assert [f.index for f in spread(frames, 2)] == [0, 3]


def test_answers_name_offered_choices_or_are_invalid() -> None:
    assert parse_choice({"frame": 2}, "frame", 3) == 2 and parse_choice({"mark": " 3 "}, "mark", 3) == 3
    for bad in ({"frame": 0}, {"frame": 4}, {"frame": True}, {"frame": "two"}, {}, "frame 2"):
        with pytest.raises(InvalidAnswer, match="1..3"):
            parse_choice(bad, "frame", 3)
    assert parse_step({"subtask": "open fridge A", "skill": "go_to_and_open"}) == ("go_to_and_open", "open fridge A")
    with pytest.raises(InvalidAnswer, match="closest: go_to_and_open"):
        parse_step({"subtask": "open it", "skill": "go_and_open"})
    with pytest.raises(InvalidAnswer, match="subtask"):
        parse_step({"subtask": "", "skill": "explore"})
    assert parse_verdict({"achieved": False, "reasoning": "no apple"}) == (False, "no apple")
    with pytest.raises(InvalidAnswer):
        parse_verdict({"achieved": "yes"})
