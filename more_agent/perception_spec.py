"""The perception mode of an episode: ground truth (the paper's) or noisy, with one rate per error kind.

``--perception gt`` is the paper's perception (S.2: "we assume accurate semantic perception").
``--perception noisy`` turns on every error kind at its default rate; ``noisy:miss=0.3,depth=0`` sets
some rates and switches others off (0). The canonical text of a spec (:meth:`PerceptionSpec.text`) is
what records, run configurations, resume keys and episode folder names carry, so two runs with the
same text perceive alike. How each kind is drawn: :mod:`more_agent.perception.noise`.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from more_agent.errors import UserError

GT = "gt"
"""The canonical text of ground-truth perception."""


class PerceptionSpec(BaseModel):
    """Rates of the perception error kinds; 0 switches a kind off. The defaults are the "realistic" ones."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    mode: Literal["gt", "noisy"] = Field(default="gt", description="'gt': every rate below is ignored.")
    confusion: float = Field(
        default=0.05,
        ge=0,
        le=1,
        description="Share of object instances seen, for the whole episode, as a sibling category in bddl's "
        "taxonomy (apple <-> pear). Fine-grained open-vocabulary detectors confuse such classes at a few per cent.",
    )
    miss: float = Field(
        default=0.2,
        ge=0,
        le=1,
        description="Chance that a typical item (0.3 m, half visible, 2.5 m away) goes undetected in one frame; "
        "it grows with range and occlusion and for small objects (noise.miss_probability).",
    )
    fragment: float = Field(
        default=0.05, ge=0, le=1, description="Share of instances seen as two instances (split at their middle)."
    )
    merge: float = Field(
        default=0.05,
        ge=0,
        le=1,
        description="Share of instances seen as part of the nearest other instance in view when the two are close.",
    )
    depth: float = Field(
        default=0.01,
        ge=0,
        le=0.5,
        description="Standard deviation of the depth error per metre of range (1 %: stereo depth cameras at 1-3 m).",
    )
    drift: float = Field(
        default=0.02,
        ge=0,
        le=1,
        description="Odometry random walk: position error std in m per sqrt(m) driven, heading half of it in "
        "rad per sqrt(m) (25 m driven: 0.1 m and 2.9 deg).",
    )
    room: float = Field(
        default=0.1,
        ge=0,
        le=1,
        description="Share of the objects the room classifier reads that it reads as a random other category.",
    )

    @property
    def noisy(self) -> bool:
        """Whether any error kind is on."""
        return self.mode == "noisy" and any(getattr(self, k) > 0 for k in ERROR_KINDS)

    def text(self) -> str:
        """The canonical text: 'gt', 'noisy' (all defaults) or 'noisy:KEY=VALUE,...' (the rates that differ)."""
        if self.mode == "gt":
            return GT
        changed = [f"{k}={getattr(self, k):g}" for k in ERROR_KINDS if getattr(self, k) != DEFAULTS[k]]
        return "noisy" + (":" + ",".join(changed) if changed else "")

    def only(self, kind: str, rate: float | None = None) -> PerceptionSpec:
        """Noisy perception with every kind off but ``kind`` (at ``rate``, default its default)."""
        rates = {k: 0.0 for k in ERROR_KINDS} | {kind: DEFAULTS[kind] if rate is None else rate}
        return PerceptionSpec(mode="noisy", **rates)


ERROR_KINDS = ("confusion", "miss", "fragment", "merge", "depth", "drift", "room")
"""The error kinds, in the order the spec's text lists them."""

DEFAULTS: dict[str, float] = {k: PerceptionSpec.model_fields[k].default for k in ERROR_KINDS}
"""The "realistic" default rate of each kind."""


def parse_perception(text: str) -> PerceptionSpec:
    """The spec a ``--perception`` value names; a UserError naming the valid keys for anything else."""
    mode, _, rest = text.strip().partition(":")
    if mode not in ("gt", "noisy"):
        raise UserError(
            f"--perception {text!r}: the mode is 'gt' or 'noisy[:KEY=VALUE,...]' (keys: {', '.join(ERROR_KINDS)})"
        )
    if mode == "gt":
        if rest:
            raise UserError(f"--perception gt takes no settings (got {text!r}); use noisy:KEY=VALUE,...")
        return PerceptionSpec()
    rates: dict[str, float] = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        key = key.strip()
        if key not in ERROR_KINDS:
            raise UserError(f"--perception: unknown error kind {key!r}; valid keys: {', '.join(ERROR_KINDS)}")
        try:
            rates[key] = float(value) if eq else float("")
        except ValueError:
            raise UserError(f"--perception {key}={value!r}: a rate is a number, e.g. {key}={DEFAULTS[key]:g}") from None
    try:
        return PerceptionSpec(mode="noisy", **rates)
    except ValidationError as e:
        bad = "; ".join(f"{err['loc'][0]}: {err['msg']}" for err in e.errors())
        raise UserError(f"--perception {text!r}: {bad} (keys: {', '.join(ERROR_KINDS)}; 0 switches one off)") from None
