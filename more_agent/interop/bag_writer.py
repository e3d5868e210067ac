"""``BagRecorder``: an episode's sensor stream as a ROS 2 bag (MCAP or sqlite3), in the message contract
``more-agent ingest`` reads (:mod:`~more_agent.interop.bag_contract`, docs/ros.md).

Per rendered frame (stamped ``index * FRAME_PERIOD_S``): depth (32FC1), colour (rgb8), semantic and
instance images (16UC1, 32SC1 past 65535), the camera info, ``/tf`` map -> base_link, the camera pose as
a PoseStamped, and the label table: the classes, every instance in view, the held item, what the robot
just opened or closed out of view and what it just put down (with its box) -- what the robot's own
perception and proprioception tell its mapping (``planners.policies.embodiment.Embodiment.sense``).
``/tf`` also holds base_link -> the optical frame with every frame: the head pans and tilts.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Literal

import numpy as np

from more_agent.interop.bag_contract import (
    CAMERA_INFO,
    IMAGE,
    POSE,
    STRING,
    TF,
    TF_TOPIC,
    BagTopics,
    InstanceLabel,
    LabelTable,
    id_encoding,
    image_fields,
    typestore,
)
from more_agent.interop.requirement import require
from more_agent.interop.transforms import matrix_pose, pose_matrix
from more_agent.robot import Observation
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.render import Frame
from more_agent.sim.world import World

FRAME_PERIOD_S = 0.1
"""Time between two recorded frames (the simulator has no clock; 10 Hz)."""

CAMERA_FRAME = "camera_optical_frame"
"""frame_id of the recorded images (OpenCV axes: x right, y down, z forward)."""

POSE_TOPIC = "/more/camera_pose"
"""Topic of the recorded camera pose (``--pose-topic`` of ingest reads it instead of /tf)."""

Storage = Literal["mcap", "sqlite3"]
STORAGES = ("mcap", "sqlite3")


class BagRecorder:
    """Writes frames to a new rosbag2 folder; use as a context manager, call ``record`` per frame."""

    def __init__(self, path: Path, *, storage: Storage = "mcap", topics: BagTopics | None = None) -> None:
        rosbag2 = require("rosbags.rosbag2", "ros")
        self.path = Path(path)
        self.topics = topics or BagTopics()
        self.frames = 0
        self._store = typestore()
        plugin = rosbag2.StoragePlugin.MCAP if storage == "mcap" else rosbag2.StoragePlugin.SQLITE3
        self._writer = rosbag2.Writer(self.path, version=rosbag2.Writer.VERSION_LATEST, storage_plugin=plugin)
        self._conns: dict[str, Any] = {}
        self._reported_open: dict[int, bool | None] = {}
        self._held: str | None = None

    def __enter__(self) -> BagRecorder:
        self._writer.open()
        t = self.topics
        for topic, msgtype in (
            (t.depth, IMAGE),
            (t.rgb, IMAGE),
            (t.semantic, IMAGE),
            (t.instance, IMAGE),
            (t.camera_info, CAMERA_INFO),
            (TF_TOPIC, TF),
            (POSE_TOPIC, POSE),
            (t.labels, STRING),
        ):
            self._conns[topic] = self._writer.add_connection(topic, msgtype, typestore=self._store)
        return self

    def __exit__(self, *exc: object) -> None:
        self._writer.close()

    def record(
        self,
        world: World,
        labels: InstanceLabels,
        frame: Frame,
        revealed: Mapping[int, tuple[np.ndarray, np.ndarray]] | None = None,
    ) -> None:
        """Write one frame rendered from ``world``'s current robot pose (before the robot's mapping fuses it),
        its instances named by ``labels`` (the robot's); ``revealed``: the boxes of what lies inside what
        the robot just opened (``Observation.revealed``)."""
        t = self.topics
        t_ns = round(self.frames * FRAME_PERIOD_S * 1e9)
        header = self._header(t_ns, CAMERA_FRAME)
        T_world_base = pose_matrix(
            (world.robot.x, world.robot.y, 0.0), (0.0, 0.0, np.sin(world.robot.yaw / 2), np.cos(world.robot.yaw / 2))
        )
        T_base_cam = np.linalg.inv(T_world_base) @ frame.T_world_cam
        self._write(
            t.labels,
            t_ns,
            self._msg(STRING, data=self._label_table(world, labels, frame, revealed or {}).model_dump_json()),
        )
        # the head pans and tilts (Robot.sense's head pose), so base -> camera is a moving joint as on a
        # real Fetch: on /tf with every frame, beside map -> base, rather than once on /tf_static
        tf = self._tf(t_ns, (t.world_frame, t.base_frame, T_world_base), (t.base_frame, CAMERA_FRAME, T_base_cam))
        self._write(TF_TOPIC, t_ns, tf)
        position, q = matrix_pose(frame.T_world_cam)
        types = self._store.types
        self._write(
            POSE_TOPIC,
            t_ns,
            self._msg(
                POSE,
                header=self._header(t_ns, t.world_frame),
                pose=types["geometry_msgs/msg/Pose"](
                    position=types["geometry_msgs/msg/Point"](*position), orientation=self._quat(q)
                ),
            ),
        )
        self._write(t.camera_info, t_ns, self._camera_info(header, frame))
        for topic, pixels, encoding in (
            (t.depth, frame.depth, "32FC1"),
            (t.rgb, frame.rgb, "rgb8"),
            (t.semantic, frame.semantic, id_encoding(frame.semantic)),
            (t.instance, frame.instance, id_encoding(frame.instance)),
        ):
            self._write(topic, t_ns, self._msg(IMAGE, header=header, **image_fields(pixels, encoding)))
        self.frames += 1

    def hook(self, world: World, labels: InstanceLabels) -> Callable[[Observation], None]:
        """An ``on_sensed`` hook (``SimRobot``) recording each sensing of ``world``, its instances named by
        ``labels`` (the robot's), with what the robot was told of the inside of what it just opened."""

        def on_sensed(seen: Observation) -> None:
            self.record(world, labels, seen.frame, revealed=seen.revealed)

        return on_sensed

    # -- the label table ----------------------------------------------------------------------------
    def _label_table(
        self, world: World, labels: InstanceLabels, frame: Frame, revealed: Mapping[int, tuple[np.ndarray, np.ndarray]]
    ) -> LabelTable:
        """Instances in view, the held one, those whose open state changed out of view (the robot just
        opened / closed them), the item just put down, with its box, and what lies inside what was just
        opened, with theirs."""
        entries = {
            iid: InstanceLabel(
                category=d["category"],
                label=d["label"],
                open=d["open"],
                held=d["held"],
                rests=_rests(world, labels, d["name"]),
            )
            for iid, d in labels.table(world, frame.instance, frame.instance_pixels).items()
        }
        by_id = {o.instance_id: o for o in world.objects.values()}
        changed = [
            iid
            for iid, was in self._reported_open.items()
            if iid not in entries and by_id[iid].openable and by_id[iid].is_open != was
        ]
        released = self._held if self._held is not None and self._held != world.robot.held else None
        placed = {}
        if released is not None:  # with what rode on it, as the simulator's robot reports it
            put_down = world.get(released)
            changed.append(put_down.instance_id)
            for rider in [put_down, *world.descendants(released)]:
                lo, hi = rider.box()
                placed[rider.instance_id] = (tuple(map(float, lo)), tuple(map(float, hi)))
        for iid in [*changed, *revealed]:
            obj = by_id[iid]
            entries.setdefault(
                iid,
                InstanceLabel(
                    category=obj.category,
                    label=labels.label(obj.name),
                    open=obj.is_open if obj.openable else None,
                    held=world.robot.held == obj.name,
                    rests=_rests(world, labels, obj.name),
                ),
            )
        self._held = world.robot.held
        self._reported_open.update({iid: e.open for iid, e in entries.items()})
        inside = {iid: (tuple(map(float, lo)), tuple(map(float, hi))) for iid, (lo, hi) in revealed.items()}
        return LabelTable(classes=list(world.class_names), instances=entries, placed=placed, revealed=inside)

    # -- messages -----------------------------------------------------------------------------------
    def _write(self, topic: str, t_ns: int, msg: Any) -> None:
        self._writer.write(self._conns[topic], t_ns, self._store.serialize_cdr(msg, msg.__msgtype__))

    def _msg(self, msgtype: str, **fields: Any) -> Any:
        return self._store.types[msgtype](**fields)

    def _header(self, t_ns: int, frame_id: str) -> Any:
        types = self._store.types
        stamp = types["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9)
        return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame_id)

    def _quat(self, q: np.ndarray) -> Any:
        return self._store.types["geometry_msgs/msg/Quaternion"](*map(float, q))

    def _tf(self, t_ns: int, *edges: tuple[str, str, np.ndarray]) -> Any:
        """One TFMessage holding each (parent, child, T_parent_child) edge, stamped ``t_ns``."""
        types = self._store.types
        stamped = []
        for parent, child, T in edges:
            translation, q = matrix_pose(T)
            transform = types["geometry_msgs/msg/Transform"](
                translation=types["geometry_msgs/msg/Vector3"](*map(float, translation)), rotation=self._quat(q)
            )
            stamped.append(
                types["geometry_msgs/msg/TransformStamped"](
                    header=self._header(t_ns, parent), child_frame_id=child, transform=transform
                )
            )
        return self._msg(TF, transforms=stamped)

    def _camera_info(self, header: Any, frame: Frame) -> Any:
        h, w = frame.depth.shape
        K = np.asarray(frame.K, dtype=np.float64)
        roi = self._store.types["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        )
        return self._msg(
            CAMERA_INFO,
            header=header,
            height=h,
            width=w,
            distortion_model="plumb_bob",
            d=np.zeros(5),
            k=K.ravel(),
            r=np.eye(3).ravel(),
            p=np.hstack([K, np.zeros((3, 1))]).ravel(),
            binning_x=0,
            binning_y=0,
            roi=roi,
        )


def _rests(world: World, labels: InstanceLabels, name: str) -> tuple[Literal["inside", "ontop"], str | None] | None:
    """How the object rests as the robot perceives it: its support link (None for a floor), None while held."""
    obj = world.get(name)
    if obj.parent is None or obj.relation is None:
        return None if world.robot.held == name else ("ontop", None)
    parent = world.get(obj.parent)
    return (obj.relation, None if parent.kind == "floor" else labels.label(parent.name))
