"""The ROS 2 message contract of ``more-agent ingest`` and ``more-agent run --bag`` (docs/ros.md).

Per camera frame a bag holds, on the topics of :class:`BagTopics` (names and frame ids are options):
depth (``sensor_msgs/msg/Image``, 32FC1 metres or 16UC1 millimetres, z-depth of the optical frame),
optional colour (rgb8 / bgr8), a semantic and an instance image (16UC1 / 32SC1 / 32UC1 / 8UC1 ids,
0 = none), all with the same ``header.stamp``; ``sensor_msgs/msg/CameraInfo`` (K); the camera pose
(``/tf`` + ``/tf_static``, or a ``geometry_msgs/msg/PoseStamped`` of the optical frame); and the label
table (``std_msgs/msg/String`` holding :class:`LabelTable` as JSON). This module holds those names,
the label table's schema and the numpy <-> ``Image`` conversions.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from more_agent.errors import UserError
from more_agent.interop.requirement import require

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
TF = "tf2_msgs/msg/TFMessage"
POSE = "geometry_msgs/msg/PoseStamped"
STRING = "std_msgs/msg/String"

DEPTH_ENCODINGS = ("32FC1", "16UC1")
"""z-depth in metres (NaN / inf / 0 invalid) or millimetres (0 invalid), REP 118."""
ID_ENCODINGS = {"8UC1": np.uint8, "16UC1": np.uint16, "32SC1": np.int32, "32UC1": np.uint32}
"""Encodings of semantic / instance images and their dtypes."""
RGB_ENCODINGS = {"rgb8": False, "bgr8": True}
"""Colour encodings, to whether the channels must be reversed."""
_DTYPES = {"32FC1": np.float32, "16UC1": np.uint16, **ID_ENCODINGS, "rgb8": np.uint8, "bgr8": np.uint8}
_CHANNELS = {"rgb8": 3, "bgr8": 3}

TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"


class BagError(UserError):
    """A bag that does not hold the contract's streams (the message names the topic)."""


class BagTopics(BaseModel):
    """Where the streams are: topic names and frame ids (``more-agent ingest`` options)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    depth: str = Field("/camera/depth/image_raw", description="Depth image topic (32FC1 m or 16UC1 mm).")
    rgb: str = Field("/camera/color/image_raw", description="Colour image topic (rgb8 / bgr8); optional in a bag.")
    semantic: str = Field("/camera/semantic/image_raw", description="Semantic class id image topic.")
    instance: str = Field("/camera/instance/image_raw", description="Instance id image topic.")
    camera_info: str = Field("/camera/depth/camera_info", description="CameraInfo of the depth camera.")
    labels: str = Field("/more/labels", description="Label table topic (std_msgs/String, JSON LabelTable).")
    pose: str | None = Field(None, description="PoseStamped of the camera's optical frame in world_frame; None: /tf.")
    world_frame: str = Field("map", description="Fixed frame the map is built in.")
    camera_frame: str | None = Field(
        None, description="Optical frame of the depth camera; None: the depth header's frame_id."
    )
    base_frame: str = Field(
        "base_link", description="Robot base frame (its x, y is the robot's position); the camera's when absent."
    )


class InstanceLabel(BaseModel):
    """What perception says about one instance id (only ``category`` is needed for a real robot)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    category: str = Field(description="Object class, e.g. 'fridge'; 'door' for doors.")
    label: str | None = Field(
        None, description="Instance label such as 'fridge A'; None: given in order of first observation."
    )
    open: bool | None = Field(None, description="Open state of an openable object; None otherwise.")
    held: bool = Field(False, description="True while the robot holds it.")
    rests: tuple[Literal["inside", "ontop"], str | None] | None = Field(
        None,
        description="How it rests ('inside' | 'ontop', label of its support, None for the floor); None: from geometry.",
    )


class LabelTable(BaseModel):
    """The label table message: class names by semantic id, and the instances' attributes."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    classes: list[str] = Field(description="Class name of each semantic id (index 0 = unlabelled); must not change.")
    instances: dict[int, InstanceLabel] = Field(default_factory=dict, description="Instance id -> attributes.")
    placed: dict[int, tuple[tuple[float, float, float], tuple[float, float, float]]] = Field(
        default_factory=dict,
        description="Instances the robot just put down, with their box (min, max corner, metres): kept in the map "
        "while no camera sees them.",
    )
    revealed: dict[int, tuple[tuple[float, float, float], tuple[float, float, float]]] = Field(
        default_factory=dict,
        description="Instances inside what the robot just opened, with their box: perceived though no camera may "
        "see them (paper S.2: all inner objects become visible once the outer object is opened).",
    )


def image_array(msg: Any, topic: str, encodings: tuple[str, ...] | dict[str, Any]) -> np.ndarray:
    """The pixels of a ``sensor_msgs/msg/Image`` as an (h, w) or (h, w, 3) array; an encoding not in
    ``encodings`` or a data size that does not fit raises a BagError naming ``topic``."""
    if msg.encoding not in encodings:
        raise BagError(f"topic {topic}: image encoding {msg.encoding!r}, expected one of {', '.join(encodings)}")
    dtype = np.dtype(_DTYPES[msg.encoding]).newbyteorder(">" if msg.is_bigendian else "<")
    channels = _CHANNELS.get(msg.encoding, 1)
    row = msg.width * channels * dtype.itemsize
    if msg.step < row or len(msg.data) < msg.step * msg.height:
        raise BagError(
            f"topic {topic}: {len(msg.data)} bytes of data do not hold a {msg.width}x{msg.height} "
            f"{msg.encoding} image with step {msg.step}"
        )
    rows = np.frombuffer(np.asarray(msg.data, dtype=np.uint8).tobytes(), dtype=np.uint8)
    rows = rows[: msg.step * msg.height].reshape(msg.height, msg.step)[:, :row]
    pixels = np.ascontiguousarray(rows).view(dtype).astype(dtype.newbyteorder("="))
    return pixels.reshape(msg.height, msg.width, channels) if channels > 1 else pixels.reshape(msg.height, msg.width)


def id_encoding(ids: np.ndarray) -> str:
    """The narrowest contract encoding for an id image: 16UC1 while ids fit, else 32SC1."""
    return "16UC1" if ids.size == 0 or (ids.min() >= 0 and ids.max() < 2**16) else "32SC1"


def image_fields(pixels: np.ndarray, encoding: str) -> dict[str, Any]:
    """``height``, ``width``, ``encoding``, ``is_bigendian``, ``step`` and ``data`` of an Image message."""
    data = np.ascontiguousarray(pixels.astype(np.dtype(_DTYPES[encoding]).newbyteorder("<")))
    return {
        "height": data.shape[0],
        "width": data.shape[1],
        "encoding": encoding,
        "is_bigendian": 0,
        "step": data.shape[1] * _CHANNELS.get(encoding, 1) * data.itemsize,
        "data": data.view(np.uint8).ravel(),
    }


def typestore() -> Any:
    """rosbags' ROS 2 Humble type store (the ``ros`` extra)."""
    typesys = require("rosbags.typesys", "ros")
    return typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
