"""The robot's head camera: intrinsics, pose maths and the constants that fix its geometry.

Conventions. World frame: x east, y north, z up, ground at z = 0; the robot's yaw is measured from
+x, counter-clockwise. Camera frame: OpenCV (x right, y down, z forward). ``T_world_cam`` maps
camera coordinates to world coordinates. Pixel (u, v) has its centre at integer coordinates, so
``K @ p_cam / p_cam[2]`` gives column / row indices directly and the principal point of a
symmetric image is ((W - 1) / 2, (H - 1) / 2).

Geometry (see docs/sensors.md for the reasons) is the robot's, :attr:`more_agent.robot_spec.RobotSpec.camera`:
256 x 256 pixels, 63.3 degrees horizontal field of view (OmniGibson's Fetch: see ``CameraSpec``) with
square pixels (so the same vertically), mounted 1.2 m above the ground (the Fetch head camera
with the torso lowered) and pitched 20 degrees down while driving (the head pans and tilts: ``camera_pose``
takes any pitch), 5 m range. The constants below name those values
for this module's callers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from more_agent.robot_spec import ROBOT

IMAGE_SIZE = ROBOT.camera.image_size
"""Width and height of every frame in pixels (paper S.2)."""

HFOV_DEG = ROBOT.camera.hfov_deg
"""Horizontal field of view in degrees."""

PITCH_DEG = ROBOT.camera.pitch_deg
"""Fixed downward tilt of the optical axis below the horizon, in degrees."""

HEAD_HEIGHT_M = ROBOT.camera.height_m
"""Height of the optical centre above the ground in metres."""

MAX_RANGE_M = ROBOT.camera.max_range_m
"""Sensor range: pixels farther than this from the camera are invalid (paper S.2), depth and semantics alike."""


@dataclass(frozen=True)
class Camera:
    """A pinhole camera rigidly mounted on the robot's head; all angles in degrees."""

    width: int = IMAGE_SIZE
    height: int = IMAGE_SIZE
    hfov_deg: float = HFOV_DEG
    pitch_deg: float = PITCH_DEG
    height_m: float = HEAD_HEIGHT_M
    max_range_m: float = MAX_RANGE_M

    @property
    def focal_px(self) -> float:
        """Focal length in pixels (square pixels: fx = fy)."""
        return (self.width / 2) / math.tan(math.radians(self.hfov_deg) / 2)

    @property
    def blind_floor_m(self) -> float:
        """Distance from the camera's foot within which the floor lies below the image's bottom edge:
        the robot never sees the floor this close to it at this pitch (0.95 m with the default geometry, 0.56 m at 90 deg)."""
        half_vfov = math.atan((self.height / 2) / self.focal_px)
        return self.height_m / math.tan(math.radians(self.pitch_deg) + half_vfov)

    def intrinsics(self) -> np.ndarray:
        """The 3x3 intrinsic matrix K (float64)."""
        f = self.focal_px
        return np.array([[f, 0.0, (self.width - 1) / 2], [0.0, f, (self.height - 1) / 2], [0.0, 0.0, 1.0]])

    def pose(self, x: float, y: float, yaw: float) -> np.ndarray:
        """T_world_cam (4x4, camera to world) for the robot base at (x, y) facing ``yaw`` radians."""
        return camera_pose(x, y, yaw, height_m=self.height_m, pitch_rad=math.radians(self.pitch_deg))

    def pixel_rays(self) -> np.ndarray:
        """Per-pixel ray directions in the camera frame, shape (H*W, 3), row-major, each with z = 1.

        Scaling a ray by t reaches the point whose z-depth is t, which is why the renderer marches
        in z-depth directly.
        """
        K = self.intrinsics()
        u, v = np.meshgrid(np.arange(self.width, dtype=np.float64), np.arange(self.height, dtype=np.float64))
        x = (u.ravel() - K[0, 2]) / K[0, 0]
        y = (v.ravel() - K[1, 2]) / K[1, 1]
        return np.stack([x, y, np.ones_like(x)], axis=1)


def camera_pose(
    x: float, y: float, yaw: float, *, height_m: float = HEAD_HEIGHT_M, pitch_rad: float = math.radians(PITCH_DEG)
) -> np.ndarray:
    """T_world_cam of a camera at (x, y, height_m) facing ``yaw`` and pitched ``pitch_rad`` down.

    The columns of the rotation are the camera's x (right), y (down) and z (forward) axes in the
    world frame.
    """
    cp, sp, cy, sy = math.cos(pitch_rad), math.sin(pitch_rad), math.cos(yaw), math.sin(yaw)
    forward = np.array([cp * cy, cp * sy, -sp])
    right = np.array([sy, -cy, 0.0])
    down = np.cross(forward, right)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = right, down, forward, (x, y, height_m)
    return T


def project(points_world: np.ndarray, K: np.ndarray, T_world_cam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (N, 2) as (u, v) and z-depths (N,) of world points (N, 3)."""
    T_cam_world = np.linalg.inv(T_world_cam)
    p = points_world @ T_cam_world[:3, :3].T + T_cam_world[:3, 3]
    uv = (p @ K.T)[:, :2] / p[:, 2:3]
    return uv, p[:, 2]
