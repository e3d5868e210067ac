"""``read_bag``: the camera frames of a ROS 2 bag (sqlite3 or MCAP) under the message contract of
:mod:`~more_agent.interop.bag_contract`, posed and labelled, one :class:`SensorFrame` at a time.

Two passes over the bag: first the small streams (camera info, label tables, ``/tf`` + ``/tf_static`` or
the pose topic), then the images, grouped by ``header.stamp``; a frame is complete when its depth,
semantic and instance images (and its colour image, when the bag has that topic) have arrived. Each
frame takes the latest camera info and label table logged at or before it (the first ones when none
came before: a latched topic recorded late). A stream that is missing, of the wrong type or in the
wrong encoding raises one :class:`~more_agent.interop.bag_contract.BagError` naming the topic.
"""

from __future__ import annotations

import bisect
import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from more_agent.interop.bag_contract import (
    CAMERA_INFO,
    DEPTH_ENCODINGS,
    ID_ENCODINGS,
    IMAGE,
    POSE,
    RGB_ENCODINGS,
    STRING,
    TF,
    TF_STATIC_TOPIC,
    TF_TOPIC,
    BagError,
    BagTopics,
    InstanceLabel,
    LabelTable,
    image_array,
    typestore,
)
from more_agent.interop.requirement import require
from more_agent.interop.transforms import TransformBuffer

MAX_PENDING_STAMPS = 64
"""Image stamps waiting for their other images before the oldest is dropped as incomplete."""


@dataclass(frozen=True, eq=False)
class SensorFrame:
    """One posed, labelled camera frame: what the mapping consumes (arrays as in ``sim.render.Frame``)."""

    stamp_s: float
    depth: np.ndarray
    """(h, w) float32 z-depth, metres, NaN where invalid."""
    semantic: np.ndarray
    instance: np.ndarray
    rgb: np.ndarray | None
    K: np.ndarray
    T_world_cam: np.ndarray
    robot_xy: tuple[float, float]
    instances: dict[int, InstanceLabel]
    """The label table's instances."""
    placed: dict[int, tuple[tuple[float, float, float], tuple[float, float, float]]]
    """Instances put down since the previous frame (a table's ``placed``, given once)."""
    revealed: dict[int, tuple[tuple[float, float, float], tuple[float, float, float]]]
    """Instances inside what the robot just opened (a table's ``revealed``, given once)."""


@dataclass
class _Stamped:
    times_ns: list[int]
    messages: list[Any]

    def at(self, t_ns: int) -> tuple[int, Any]:
        """Index and message of the latest entry logged at or before ``t_ns`` (the first when none)."""
        i = max(bisect.bisect(self.times_ns, t_ns) - 1, 0)
        return i, self.messages[i]


class BagStream:
    """An opened bag: its class names and its frames (``frames()``, once)."""

    def __init__(self, path: Path, topics: BagTopics | None = None) -> None:
        self.path = Path(path)
        self.topics = topics or BagTopics()
        self.skipped = 0
        """Image stamps dropped because a stream had no image with that stamp."""
        rosbag2 = require("rosbags.rosbag2", "ros")
        if not self.path.exists():
            raise BagError(f"no bag at {self.path}")
        self._store = typestore()
        try:
            self._reader = rosbag2.Reader(self.path)
            self._reader.open()
        except Exception as e:  # noqa: BLE001 - rosbags raises several types for unreadable bags
            raise BagError(f"cannot read the bag {self.path}: {type(e).__name__}: {e}") from None
        self._conns = {c.topic: c for c in self._reader.connections}
        t = self.topics
        self._images = {
            role: self._connection(topic, IMAGE, role, option)
            for role, topic, option in (
                ("depth", t.depth, "--depth-topic"),
                ("semantic", t.semantic, "--semantic-topic"),
                ("instance", t.instance, "--instance-topic"),
            )
        }
        if t.rgb in self._conns:
            self._images["rgb"] = self._connection(t.rgb, IMAGE, "colour", "--rgb-topic")
        self._info = self._stamped(self._connection(t.camera_info, CAMERA_INFO, "camera info", "--camera-info-topic"))
        labels = self._connection(t.labels, STRING, "label table", "--labels-topic")
        self._tables = self._stamped(labels, lambda m: self._table(m.data))
        self.class_names = list(self._tables.messages[0].classes)
        for table in self._tables.messages:
            if table.classes[: len(self.class_names)] != self.class_names:
                raise BagError(
                    f"topic {t.labels}: the class list changed within the bag (classes may only be appended)"
                )
        self._tf = self._transforms()
        self._last_table = -1

    def close(self) -> None:
        self._reader.close()

    # -- the small streams --------------------------------------------------------------------------
    def _connection(self, topic: str, msgtype: str, role: str, option: str) -> Any:
        conn = self._conns.get(topic)
        if conn is None:
            have = ", ".join(f"{c.topic} ({c.msgtype})" for c in self._conns.values()) or "none"
            raise BagError(
                f"the bag {self.path} has no topic {topic} (the {role} stream, {msgtype}); set {option}. "
                f"Topics in the bag: {have}"
            )
        if conn.msgtype != msgtype:
            raise BagError(f"topic {topic} (the {role} stream) holds {conn.msgtype}, expected {msgtype}")
        return conn

    def _stamped(self, conn: Any, convert: Any = None) -> _Stamped:
        times, messages = [], []
        for _, t_ns, raw in self._reader.messages(connections=[conn]):
            msg = self._store.deserialize_cdr(raw, conn.msgtype)
            times.append(t_ns)
            messages.append(convert(msg) if convert else msg)
        if not messages:
            raise BagError(f"topic {conn.topic} has no messages")
        order = np.argsort(times, kind="stable")
        return _Stamped([times[i] for i in order], [messages[i] for i in order])

    def _table(self, text: str) -> LabelTable:
        try:
            return LabelTable.model_validate(json.loads(text))
        except (json.JSONDecodeError, ValidationError) as e:
            raise BagError(
                f"topic {self.topics.labels}: not a label table (docs/ros.md): {str(e).splitlines()[0]}"
            ) from None

    def _transforms(self) -> TransformBuffer:
        tf = TransformBuffer()
        t = self.topics
        if t.pose is not None:
            for msg in self._stamped(self._connection(t.pose, POSE, "pose", "--pose-topic")).messages:
                p = msg.pose
                tf.add(
                    msg.header.frame_id,
                    t.pose,
                    _seconds(msg.header.stamp),
                    (p.position.x, p.position.y, p.position.z),
                    (p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w),
                )
            return tf
        conns = [self._connection(TF_TOPIC, TF, "transforms", "--pose-topic")]
        if TF_STATIC_TOPIC in self._conns:
            conns.append(self._connection(TF_STATIC_TOPIC, TF, "static transforms", "--pose-topic"))
        for conn, _, raw in self._reader.messages(connections=conns):
            for tr in self._store.deserialize_cdr(raw, conn.msgtype).transforms:
                q, v = tr.transform.rotation, tr.transform.translation
                tf.add(
                    tr.header.frame_id,
                    tr.child_frame_id,
                    _seconds(tr.header.stamp),
                    (v.x, v.y, v.z),
                    (q.x, q.y, q.z, q.w),
                    static=conn.topic == TF_STATIC_TOPIC,
                )
        return tf

    def _camera_frame(self, depth_msg: Any) -> str:
        """The frame whose pose is the camera's: the pose topic's own (its poses are the camera's), else
        --camera-frame, else the depth image's frame_id."""
        return self.topics.pose or self.topics.camera_frame or depth_msg.header.frame_id

    # -- the frames ---------------------------------------------------------------------------------
    def frames(self) -> Iterator[SensorFrame]:
        """The complete frames in stamp order of arrival; a bag without one raises a BagError."""
        roles = {conn.id: role for role, conn in self._images.items()}
        pending: dict[int, dict[str, tuple[int, Any]]] = {}
        count = 0
        for conn, t_ns, raw in self._reader.messages(connections=list(self._images.values())):
            msg = self._store.deserialize_cdr(raw, conn.msgtype)
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            parts = pending.setdefault(stamp, {})
            parts[roles[conn.id]] = (t_ns, msg)
            if len(parts) == len(self._images):
                del pending[stamp]
                count += 1
                yield self._frame(parts)
            elif len(pending) > MAX_PENDING_STAMPS:
                del pending[min(pending)]
                self.skipped += 1
        self.skipped += len(pending)
        if count == 0:
            seen = {role for parts in pending.values() for role in parts}
            missing = [self._images[r].topic for r in self._images if r not in seen] or [
                c.topic for c in self._images.values()
            ]
            raise BagError(
                f"no complete frame in {self.path}: no image on {', '.join(missing)} shares a "
                "header.stamp with the other image topics"
            )

    def _frame(self, parts: dict[str, tuple[int, Any]]) -> SensorFrame:
        t = self.topics
        t_ns, depth_msg = parts["depth"]
        depth = image_array(depth_msg, t.depth, DEPTH_ENCODINGS).astype(np.float32)
        if depth_msg.encoding == "16UC1":
            depth /= 1000.0
        depth[~(depth > 0)] = np.nan  # 0, negative, NaN: invalid; +inf stays non-finite
        depth[~np.isfinite(depth)] = np.nan
        semantic = image_array(parts["semantic"][1], t.semantic, ID_ENCODINGS).astype(np.int32)
        instance = image_array(parts["instance"][1], t.instance, ID_ENCODINGS).astype(np.int32)
        rgb = None
        if "rgb" in parts:
            msg = parts["rgb"][1]
            rgb = image_array(msg, t.rgb, RGB_ENCODINGS)
            rgb = rgb[..., ::-1].copy() if RGB_ENCODINGS[msg.encoding] else rgb
        for topic, img in ((t.semantic, semantic), (t.instance, instance), (t.rgb, rgb)):
            if img is not None and img.shape[:2] != depth.shape:
                raise BagError(
                    f"topic {topic}: a {img.shape[1]}x{img.shape[0]} image for a "
                    f"{depth.shape[1]}x{depth.shape[0]} depth image"
                )
        info = self._info.at(t_ns)[1]
        if (info.width, info.height) != (depth.shape[1], depth.shape[0]):
            raise BagError(
                f"topic {t.camera_info}: camera info for {info.width}x{info.height}, depth images are "
                f"{depth.shape[1]}x{depth.shape[0]}"
            )
        stamp_s = _seconds(depth_msg.header.stamp)
        T_world_cam = self._tf.lookup(t.world_frame, self._camera_frame(depth_msg), stamp_s)
        robot = (
            self._tf.lookup(t.world_frame, t.base_frame, stamp_s) if self._tf.knows(t.base_frame) else T_world_cam
        )[:2, 3]
        index, table = self._tables.at(t_ns)
        fresh = index != self._last_table
        self._last_table = index
        return SensorFrame(
            stamp_s=stamp_s,
            depth=depth,
            semantic=semantic,
            instance=instance,
            rgb=rgb,
            K=np.asarray(info.k, dtype=float).reshape(3, 3),
            T_world_cam=T_world_cam,
            robot_xy=(float(robot[0]), float(robot[1])),
            instances=dict(table.instances),
            placed=dict(table.placed) if fresh else {},
            revealed=dict(table.revealed) if fresh else {},
        )


def _seconds(stamp: Any) -> float:
    return stamp.sec + stamp.nanosec * 1e-9
