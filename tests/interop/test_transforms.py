"""The transform buffer: chains, interpolation, and the errors for frames and stamps it cannot give."""

from __future__ import annotations

import math

import numpy as np
import pytest

from more_agent.interop.bag_contract import BagError
from more_agent.interop.transforms import TransformBuffer, matrix_pose, pose_matrix


def _yaw(theta: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2))


def test_a_chain_composes_parent_to_child_and_interpolates_between_samples():
    tf = TransformBuffer()
    tf.add("map", "base", 0.0, (0.0, 0.0, 0.0), _yaw(0.0))
    tf.add("map", "base", 1.0, (2.0, 0.0, 0.0), _yaw(math.pi / 2))
    tf.add("base", "cam", 0.0, (0.0, 0.0, 1.0), _yaw(0.0), static=True)
    at_half = tf.lookup("map", "cam", 0.5)
    assert np.allclose(at_half[:3, 3], (1.0, 0.0, 1.0))
    assert np.allclose(at_half[:3, :3], pose_matrix((0, 0, 0), _yaw(math.pi / 4))[:3, :3])
    assert np.allclose(tf.lookup("map", "cam", 1.0)[:3, 3], (2.0, 0.0, 1.0))
    assert tf.knows("base") and not tf.knows("map")


def test_matrix_pose_inverts_pose_matrix():
    T = pose_matrix((1.0, -2.0, 0.5), _yaw(2.0))
    t, q = matrix_pose(T)
    assert np.allclose(pose_matrix(t, q), T)


def test_unknown_frames_and_stamps_far_outside_the_samples_fail():
    tf = TransformBuffer(max_gap_s=0.1)
    tf.add("map", "base", 1.0, (0.0, 0.0, 0.0), _yaw(0.0))
    tf.add("map", "base", 2.0, (1.0, 0.0, 0.0), _yaw(0.0))
    assert np.allclose(tf.lookup("map", "base", 2.05)[:3, 3], (1.0, 0.0, 0.0))  # within the gap: the last sample
    with pytest.raises(BagError, match="outside its samples"):
        tf.lookup("map", "base", 3.0)
    with pytest.raises(BagError, match="no transform from 'cam' to 'map'"):
        tf.lookup("map", "cam", 1.0)
    with pytest.raises(BagError, match="two parents"):
        tf.add("odom", "base", 1.5, (0.0, 0.0, 0.0), _yaw(0.0))
