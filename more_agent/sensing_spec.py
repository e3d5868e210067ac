"""The sensing cadence of an episode: how far the robot moves or turns between two frames it fuses on the way.

A real robot's mapper does not fuse every camera frame; like the keyframe selection of visual SLAM and
volumetric mappers, it takes a new frame once the camera has moved or turned far enough since the last
fused one (``planners.policies.sensing.SensingSchedule`` applies the rule). Frames where the robot stops
(arrival, a blocked move, a manipulation, every view of a look-around) are fused regardless.

``--sensing 1m/45deg``, the default, fuses a frame once the base has driven 1 m or turned 45 deg (below
the 63.3 deg field of view of the Fetch's camera, so consecutive frames overlap; the Fetch drives at up
to 1 m/s, so a mapper fusing once a second at full speed). Against a frame every 0.3 m and after every
turn, its maps and graphs agree within the tolerance docs/sensors.md states ("Sensing cadence"), and
the pipeline-ceiling SR is the same. ``--sensing 0.5m/30deg`` is the cadence of the versions before
1m/45deg became the default (BUMBLE's rule for keeping frames). The canonical text
(:meth:`SensingCadence.text`) is what records, run configurations, resume keys and folder names carry.
"""

from __future__ import annotations

import re

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from more_agent.errors import UserError
from more_agent.robot_spec import ROBOT


class SensingCadence(BaseModel):
    """How far the robot moves or turns between two frames fused on the way."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    distance_m: float = Field(
        default=1.0, gt=0, description="Fuse a frame once the base moved this far since the last one."
    )
    angle_deg: float = Field(
        default=45.0,
        gt=0,
        lt=ROBOT.camera.hfov_deg,
        description="... or turned this far (below the camera's field of view).",
    )

    def text(self) -> str:
        """The canonical text, e.g. '1m/45deg'."""
        return f"{self.distance_m:g}m/{self.angle_deg:g}deg"

    def at_least_as_often_as(self, other: SensingCadence) -> SensingCadence:
        """The cadence that fuses a frame whenever this one or ``other`` would: the shorter distance and angle."""
        return SensingCadence(
            distance_m=min(self.distance_m, other.distance_m), angle_deg=min(self.angle_deg, other.angle_deg)
        )


DEFAULT_SENSING = SensingCadence().text()
"""The canonical text of the default cadence."""

LEGACY_SENSING = "0.5m/30deg"
"""The cadence of the versions before the option (records of schema 5 and older)."""

_TEXT = re.compile(r"\s*(?P<distance>[0-9.]+)\s*m\s*/\s*(?P<angle>[0-9.]+)\s*deg\s*")


def parse_sensing(text: str) -> SensingCadence:
    """The cadence a ``--sensing`` value names ('DISTANCEm/ANGLEdeg'); a UserError with an example otherwise."""
    match = _TEXT.fullmatch(text)
    example = f"e.g. {DEFAULT_SENSING} (the default) or {LEGACY_SENSING}"
    if match is None:
        raise UserError(f"--sensing {text!r}: write DISTANCEm/ANGLEdeg, {example}")
    try:
        return SensingCadence(distance_m=float(match["distance"]), angle_deg=float(match["angle"]))
    except (ValueError, ValidationError):
        raise UserError(
            f"--sensing {text!r}: the distance is above 0 m and the angle between 0 and "
            f"{ROBOT.camera.hfov_deg:.1f} deg (the camera's field of view), {example}"
        ) from None
