"""``TransformBuffer``: the frame tree of a bag's ``/tf`` and ``/tf_static`` (and pose topic), looked up
at a time stamp, as tf2 does: translation interpolated linearly, rotation by slerp between the two
samples around the stamp; a stamp outside a transform's samples by more than ``max_gap_s`` fails."""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation, Slerp

from more_agent.interop.bag_contract import BagError

MAX_GAP_S = 0.1
"""How far (seconds) a lookup may lie before the first or after the last sample of a transform."""


def pose_matrix(translation: ArrayLike, quaternion_xyzw: ArrayLike) -> np.ndarray:
    """4x4 homogeneous transform of a translation and a unit quaternion (x, y, z, w, as ROS writes it)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(quaternion_xyzw).as_matrix()
    T[:3, 3] = translation
    return T


def matrix_pose(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Translation and quaternion (x, y, z, w) of a 4x4 rigid transform."""
    return T[:3, 3].copy(), Rotation.from_matrix(T[:3, :3]).as_quat()


@dataclass
class _Edge:
    parent: str
    stamps: list[float] = field(default_factory=list)
    translations: list[np.ndarray] = field(default_factory=list)
    quaternions: list[np.ndarray] = field(default_factory=list)
    static: bool = False


class TransformBuffer:
    """Transforms parent <- child over time; ``lookup(target, source, t)`` gives T_target_source."""

    def __init__(self, max_gap_s: float = MAX_GAP_S) -> None:
        self.max_gap_s = max_gap_s
        self._edges: dict[str, _Edge] = {}

    def add(
        self,
        parent: str,
        child: str,
        stamp_s: float,
        translation: ArrayLike,
        quaternion_xyzw: ArrayLike,
        *,
        static: bool = False,
    ) -> None:
        """One sample of the pose of ``child`` in ``parent`` (a frame has one parent, as in tf2)."""
        edge = self._edges.setdefault(child, _Edge(parent=parent, static=static))
        if edge.parent != parent:
            raise BagError(f"frame {child!r} has two parents in the transforms: {edge.parent!r} and {parent!r}")
        i = bisect.bisect(edge.stamps, stamp_s)
        edge.stamps.insert(i, stamp_s)
        edge.translations.insert(i, np.asarray(translation, dtype=float))
        edge.quaternions.insert(i, np.asarray(quaternion_xyzw, dtype=float))

    def knows(self, frame: str) -> bool:
        """Whether ``frame`` is the child of any transform."""
        return frame in self._edges

    def lookup(self, target: str, source: str, stamp_s: float) -> np.ndarray:
        """T_target_source at ``stamp_s``: the chain from ``source`` up to ``target``."""
        T = np.eye(4)
        frame = source
        seen: list[str] = []
        while frame != target:
            edge = self._edges.get(frame)
            if edge is None:
                chain = " -> ".join([*seen, frame])
                raise BagError(
                    f"no transform from {source!r} to {target!r} at t={stamp_s:.3f} s (chain {chain} ends "
                    f"at {frame!r}); check --world-frame / --camera-frame or the /tf topics"
                )
            T = self._at(edge, frame, stamp_s) @ T
            seen.append(frame)
            frame = edge.parent
        return T

    def _at(self, edge: _Edge, child: str, t: float) -> np.ndarray:
        if edge.static or len(edge.stamps) == 1:
            if not edge.static and abs(t - edge.stamps[0]) > self.max_gap_s:
                raise BagError(
                    f"transform {edge.parent} -> {child}: no sample within {self.max_gap_s} s of t={t:.3f} s"
                )
            return pose_matrix(edge.translations[0], edge.quaternions[0])
        i = bisect.bisect(edge.stamps, t)
        if i == 0 or i == len(edge.stamps):
            end = 0 if i == 0 else -1
            if abs(t - edge.stamps[end]) > self.max_gap_s:
                raise BagError(
                    f"transform {edge.parent} -> {child}: t={t:.3f} s is outside its samples "
                    f"[{edge.stamps[0]:.3f}, {edge.stamps[-1]:.3f}] s"
                )
            return pose_matrix(edge.translations[end], edge.quaternions[end])
        t0, t1 = edge.stamps[i - 1], edge.stamps[i]
        w = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
        if w == 0.0:
            return pose_matrix(edge.translations[i - 1], edge.quaternions[i - 1])
        translation = (1 - w) * edge.translations[i - 1] + w * edge.translations[i]
        slerp = Slerp([0.0, 1.0], Rotation.from_quat([edge.quaternions[i - 1], edge.quaternions[i]]))
        return pose_matrix(translation, slerp([w]).as_quat()[0])
