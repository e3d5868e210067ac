"""The scene format: a floor plan with rooms, walls, doors, windows and furniture.

A scene is static input: what stands where before a task adds its objects. It is stored as
versioned JSON (``Scene.model_dump_json``) that a user may also write by hand; ``load_scene``
validates it and reports the path of the first bad field. Geometry is metric, in the world frame:
x east, y north, z up, the ground at z = 0. Every box is axis-aligned.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError, model_validator

from more_agent.errors import UserError

SCENE_SCHEMA_VERSION: Literal[1] = 1

GroundClass = Literal["floor", "carpet", "lawn", "driveway"]
"""Ground classes; all four are free space for the robot (paper S.2)."""

FREE_SPACE_CLASSES: tuple[str, ...] = ("floor", "carpet", "lawn", "driveway")

STRUCTURAL_CLASSES: tuple[str, ...] = ("unlabeled", "floor", "carpet", "lawn", "driveway", "wall", "door", "window")
"""Semantic classes with fixed ids (their index); object categories follow, per world."""

MAX_COORD_M = 1_000.0
"""Largest coordinate or size of a scene file in metres (a typo like 1e9 is rejected, not allocated)."""

MAX_SCENE_EXTENT_M = 200.0
"""Largest width or depth of a scene (generated BEHAVIOR-1K plans span up to about 95 m); bounds the map grids."""

Metres = Annotated[float, Field(ge=-MAX_COORD_M, le=MAX_COORD_M)]
"""A finite coordinate or length in metres within +-MAX_COORD_M."""

Bounds2D = tuple[Metres, Metres, Metres, Metres]
"""(xmin, ymin, xmax, ymax) in metres."""


def _ordered(b: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    if not (b[0] < b[2] and b[1] < b[3]):
        raise ValueError(f"bounds must satisfy xmin < xmax and ymin < ymax, got {list(b)}")
    return b


Footprint = Annotated[Bounds2D, AfterValidator(_ordered)]
"""Bounds2D of a non-empty rectangle: xmin < xmax and ymin < ymax."""

Vec3 = tuple[Metres, Metres, Metres]


class SceneError(UserError, ValueError):
    """A scene file or scene name that cannot be used; the message says where and why."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Room(_Strict):
    """A room or outdoor region; its footprint is an axis-aligned rectangle."""

    id: str = Field(description="BEHAVIOR room instance name, e.g. 'kitchen_0'.")
    type: str = Field(description="BEHAVIOR room type, e.g. 'kitchen', 'garden'.")
    bounds: Footprint = Field(description="Footprint (xmin, ymin, xmax, ymax) in metres.")
    ground: GroundClass = Field(default="floor", description="Ground class of the footprint.")
    outdoor: bool = Field(default=False, description="True for gardens, driveways and other open-air regions.")


class Wall(_Strict):
    """A solid axis-aligned wall box from z_min to z_max (window openings split walls vertically)."""

    bounds: Footprint = Field(description="Footprint (xmin, ymin, xmax, ymax) in metres.")
    z_min: Metres = Field(default=0.0, description="Bottom of the box in metres.")
    z_max: Metres = Field(default=2.6, description="Top of the box in metres.")

    @model_validator(mode="after")
    def _valid(self) -> Wall:
        if self.z_max <= self.z_min:
            raise ValueError(f"wall z_max must exceed z_min, got {self.z_min}..{self.z_max}")
        return self


class Window(_Strict):
    """A see-through opening in a wall between sill and top height; not passable."""

    id: str
    bounds: Bounds2D = Field(description="Footprint of the opening within its wall.")
    sill: Metres = Field(default=0.9, description="Bottom of the glass in metres.")
    top: Metres = Field(default=2.0, description="Top of the glass in metres.")
    rooms: tuple[str, ...] = Field(default=(), description="Rooms on either side (one for an exterior window).")


class Door(_Strict):
    """An articulated interior door in a wall gap, connecting two rooms.

    Exterior doors (to the empty world outside) are closed and removed from scenes, as in the
    paper (S.2), so every door here connects two rooms of the scene.
    """

    id: str = Field(description="Readable id, e.g. 'door_3'.")
    rooms: tuple[str, str] = Field(description="The two rooms it connects.")
    center: tuple[Metres, Metres] = Field(description="Centre of the opening (x, y) in metres.")
    width: float = Field(gt=0.3, le=MAX_COORD_M, description="Clear width of the opening in metres.")
    axis: Literal["x", "y"] = Field(description="World axis along which the opening extends (the wall's direction).")
    thickness: float = Field(default=0.1, gt=0, le=MAX_COORD_M, description="Wall thickness at the door in metres.")
    height: float = Field(
        default=2.1, gt=1.0, le=MAX_COORD_M, description="Height of the opening; a lintel sits above it."
    )
    open: bool = Field(default=True, description="Initial state.")

    @model_validator(mode="after")
    def _two_rooms(self) -> Door:
        if self.rooms[0] == self.rooms[1]:
            raise ValueError(f"a door joins two different rooms, got {self.rooms[0]!r} twice")
        return self

    def bounds(self) -> Bounds2D:
        """Footprint of the door leaf / opening."""
        hw, ht = self.width / 2, self.thickness / 2
        x, y = self.center
        return (x - hw, y - ht, x + hw, y + ht) if self.axis == "x" else (x - ht, y - hw, x + ht, y + hw)


class GroundPatch(_Strict):
    """A rectangle of another ground class inside a room: a carpet under a rug, a garden's driveway."""

    room: str = Field(description="Id of the room it lies in.")
    bounds: Footprint = Field(description="Footprint (xmin, ymin, xmax, ymax) in metres, within the room.")
    ground: GroundClass = Field(description="Ground class of the patch; it overrides the room's ground.")


class Furniture(_Strict):
    """A piece of scene furniture (fixed in place): an axis-aligned box, maybe openable."""

    id: str = Field(description="Readable id, e.g. 'fridge_0'.")
    category: str = Field(description="BEHAVIOR-1K object category, e.g. 'fridge', 'bottom_cabinet'.")
    synset: str | None = Field(default=None, description="WordNet-style synset, e.g. 'electric_refrigerator.n.01'.")
    model: str | None = Field(default=None, description="BEHAVIOR-1K model id the size was taken from.")
    room: str = Field(description="Id of the room it stands in.")
    center: Vec3 = Field(description="Centre of the bounding box (x, y, z) in metres.")
    size: Vec3 = Field(description="Bounding box extents (sx, sy, sz) in metres, after rotation.")
    openable: bool = Field(default=False, description="Has a door, lid or drawer the robot can open.")
    open: bool = Field(default=False, description="Initial state; only meaningful when openable.")

    @model_validator(mode="after")
    def _valid(self) -> Furniture:
        if min(self.size) <= 0:
            raise ValueError(f"furniture size must be positive, got {list(self.size)}")
        if self.open and not self.openable:
            raise ValueError("furniture cannot be open when it is not openable")
        return self


class Scene(_Strict):
    """A whole floor plan; ``bounds`` encloses every room."""

    schema_version: Literal[1] = Field(default=SCENE_SCHEMA_VERSION, description="Scene format version.")
    name: str = Field(description="Scene name, e.g. 'Rs_int'.")
    seed: int = Field(default=0, description="Seed the plan was generated with (0 for hand-written scenes).")
    bounds: Footprint = Field(description="Extent of the plan (xmin, ymin, xmax, ymax) in metres.")
    wall_height: float = Field(default=2.6, gt=0, le=MAX_COORD_M)
    rooms: list[Room] = Field(min_length=1)
    walls: list[Wall] = Field(default_factory=list)
    doors: list[Door] = Field(default_factory=list)
    windows: list[Window] = Field(default_factory=list)
    furniture: list[Furniture] = Field(default_factory=list)
    ground_patches: list[GroundPatch] = Field(default_factory=list, description="Carpets and driveways within rooms.")

    @model_validator(mode="after")
    def _consistent(self) -> Scene:
        extent = max(self.bounds[2] - self.bounds[0], self.bounds[3] - self.bounds[1])
        if extent > MAX_SCENE_EXTENT_M:
            raise ValueError(f"scene bounds span {extent:g} m, over the limit of {MAX_SCENE_EXTENT_M:g} m")
        room_ids = [r.id for r in self.rooms]
        _unique(room_ids, "room")
        _unique([d.id for d in self.doors] + [f.id for f in self.furniture] + [w.id for w in self.windows], "object")
        known = set(room_ids)
        for i, d in enumerate(self.doors):
            for r in d.rooms:
                if r not in known:
                    raise ValueError(f"doors[{i}] ({d.id}) names unknown room {r!r}")
        for i, f in enumerate(self.furniture):
            if f.room not in known:
                raise ValueError(f"furniture[{i}] ({f.id}) names unknown room {f.room!r}")
        for i, p in enumerate(self.ground_patches):
            if p.room not in known:
                raise ValueError(f"ground_patches[{i}] names unknown room {p.room!r}")
        return self

    def room(self, room_id: str) -> Room:
        """The room with this id (KeyError if none)."""
        for r in self.rooms:
            if r.id == room_id:
                return r
        raise KeyError(room_id)


def _unique(ids: list[str], what: str) -> None:
    seen: set[str] = set()
    for i in ids:
        if i in seen:
            raise ValueError(f"duplicate {what} id {i!r}")
        seen.add(i)


def format_validation_error(err: ValidationError, source: str) -> str:
    """One readable message naming the path of each bad field, e.g. ``rooms[2].bounds``."""
    lines = []
    for e in err.errors():
        path = ""
        for part in e["loc"]:
            path += f"[{part}]" if isinstance(part, int) else (f".{part}" if path else str(part))
        lines.append(f"{path or '<root>'}: {e['msg']}")
    return f"invalid scene file {source}: " + "; ".join(lines)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene JSON file; raise SceneError naming the bad field's path."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneError(f"scene file not found: {path}") from None
    except json.JSONDecodeError as e:
        raise SceneError(f"scene file {path} is not valid JSON: line {e.lineno} column {e.colno}: {e.msg}") from None
    except RecursionError:
        raise SceneError(f"scene file {path} is nested too deeply to be a scene") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(f"cannot read scene file {path}: {getattr(e, 'strerror', None) or e}") from None
    try:
        return Scene.model_validate(data)
    except ValidationError as e:
        raise SceneError(format_validation_error(e, str(path))) from None


def save_scene(scene: Scene, path: str | Path) -> None:
    """Write a scene as indented JSON."""
    Path(path).write_text(scene.model_dump_json(indent=1))
