"""The robot's body in numbers: one :class:`RobotSpec`, read by the world, the simulator and the planners.

Everything that says how big the robot is, how far its arm reaches and what its head camera sees is
defined here once (:data:`ROBOT`). The simulator moves and renders with it; the planners plan with
it; neither keeps its own copy. A real robot would fill in its own.

Two clearances elsewhere are the radius plus a margin, not other radii: paths on the agent's own
map keep ``radius_m`` + 0.05 m from mapped obstacles (``PolicyConfig.plan_inflation_m``, since that
map is coarse and noisy), and the floor-plan generator furnishes rooms for a robot 0.1 m wider and
an arm 0.5 m shorter than this one (``sim.floorplan.generate_floorplan``), so every generated piece
is comfortably reachable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

OMNIGIBSON_FOCAL_LENGTH_MM = 17.0
"""Focal length OmniGibson's ``VisionSensor`` sets on every robot camera, the Fetch's head camera included."""

USD_HORIZONTAL_APERTURE_MM = 20.955
"""Horizontal aperture of a USD camera that sets none (OmniGibson leaves the USD default)."""

OMNIGIBSON_FETCH_HFOV_DEG = math.degrees(2 * math.atan(USD_HORIZONTAL_APERTURE_MM / (2 * OMNIGIBSON_FOCAL_LENGTH_MM)))
"""The paper's Fetch head camera in OmniGibson: 63.3 degrees horizontally (``CameraSpec``)."""


@dataclass(frozen=True)
class CameraSpec:
    """The head camera: a pinhole with square pixels, rigidly mounted, pitched down (docs/sensors.md).

    The field of view is the paper's Fetch in OmniGibson: its ``VisionSensor`` sets a 17 mm focal length
    and keeps USD's default 20.955 mm horizontal aperture, 2 atan(20.955 / 34) = 63.3 degrees
    (:data:`OMNIGIBSON_FETCH_HFOV_DEG`). The default is still 90 degrees: with 63.3 the loop loses
    episodes through defects the narrower view exposes (docs/sensors.md), so the alignment waits on
    them. With 90 degrees the ground is visible from 0.56 m in front of the robot and a 2.1 m door
    lintel from 1.9 m away (0.95 m and 4.4 m with 63.3).
    """

    image_size: int = 256
    """Width and height of every frame in pixels (paper S.2)."""
    hfov_deg: float = 90.0
    """Horizontal field of view in degrees (square pixels: the vertical one is the same)."""
    pitch_deg: float = 20.0
    """Fixed downward tilt of the optical axis below the horizon, in degrees."""
    height_m: float = 1.2
    """Height of the optical centre above the ground (the Fetch head camera with the torso lowered)."""
    max_range_m: float = 5.0
    """Sensor range: pixels whose z-depth exceeds it are invalid (paper S.2)."""


@dataclass(frozen=True)
class RobotSpec:
    """Size, reach and camera of the robot (a Fetch with its torso lowered, paper S.2-S.3)."""

    radius_m: float = 0.2
    """Radius of the base's collision disc: the clearance the simulator's moves and its ground-truth
    navigation grid keep from walls, closed doors and furniture. Smaller than Fetch's ~0.28 m base, so
    that 0.9 m doors and 0.8 m corridors stay passable (docs/sensors.md)."""
    reach_m: float = 1.5
    """Largest horizontal distance from the base to an object's footprint for a manipulation."""
    reach_top_m: float = 1.6
    """Highest surface the arm places on; a support with inner levels whose top is higher takes items on
    top on its highest level at most this high (``sim.packing.support_surface``)."""
    camera: CameraSpec = field(default_factory=CameraSpec)


ROBOT = RobotSpec()
"""The robot every episode runs with."""

FORWARD_STEP_M = 0.075
"""Length of one low-level forward move (paper S.3)."""

MAX_TURN_RAD = math.radians(35)
"""Largest low-level turn (paper S.3)."""


def full_turn_angles(max_turn: float = MAX_TURN_RAD) -> list[float]:
    """Equal left turns of at most ``max_turn`` that add up to one full turn (11 of 32.7 deg for 35 deg)."""
    n = math.ceil(2 * math.pi / max_turn - 1e-9)
    return [2 * math.pi / n] * n
