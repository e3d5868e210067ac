"""Scene-graph data model: root / regions / objects with typed attributes, spatial relations, the
sparse Voronoi navigation graph and the BEV occupancy grid. Versioned JSON via pydantic
(``SceneGraph.model_dump_json``; the occupancy grid is left out of JSON). Builder scratch state
(voxels, viewpoints, id memory) lives in ``builder.py``, never here.

Ids: regions are ``region_<k>``; objects are keyed by their alphabetical instance label
(e.g. ``"fridge A"``); the root is ``"root"``.

Each relation of the hierarchy is stored once: an object names its region (``ObjectNode.region_id``;
``SceneGraph.objects_in`` derives a region's objects) and says whether the robot holds it
(``ObjectNode.held``; ``SceneGraph.held_object`` derives the robot's). ``SceneGraph`` checks on
construction that a held object has no region, every other object's region is in the graph and the
robot holds at most one object.
"""

from __future__ import annotations

from collections.abc import Iterable
from enum import Enum
from typing import Annotated

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, PlainSerializer, PrivateAttr, model_validator
from scipy.spatial import cKDTree

from more_agent import vocabulary
from more_agent.sim.grid import Grid

SCHEMA_VERSION = 2

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]


def _as(dtype: type) -> BeforeValidator:
    """Validation into a numpy array of ``dtype`` (JSON gives lists)."""
    return BeforeValidator(lambda v: np.asarray(v, dtype=dtype))


_AS_LIST = PlainSerializer(lambda a: a.tolist(), return_type=list)

FloatArray = Annotated[np.ndarray, _as(np.float64), _AS_LIST]
IntArray = Annotated[np.ndarray, _as(np.int64), _AS_LIST]
BoolArray = Annotated[np.ndarray, _as(np.bool_), _AS_LIST]


class Layer(str, Enum):
    """Layers of the hierarchy."""

    ROOT = "root"
    REGION = "region"
    OBJECT = "object"


class _Model(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", arbitrary_types_allowed=True)


class Box3D(_Model):
    """Axis-aligned box in world metres."""

    min: Vec3 = Field(description="(x, y, z) minimum corner.")
    max: Vec3 = Field(description="(x, y, z) maximum corner.")


class ObjectNode(_Model):
    """An observed object (doors included, category 'door')."""

    id: str = Field(description="Readable id: the instance label.")
    category: str = Field(description="Object category.")
    instance_id: int = Field(description="Instance id in the segmentation.")
    label: str = Field(description="Alphabetical instance label as in the paper, e.g. 'fridge A'.")
    region_id: str | None = Field(description="Region it is assigned to (Eq. 1); None while held.")
    position: Vec3 = Field(description="Centre of its observed bounding box, metres.")
    bbox: Box3D = Field(description="Observed axis-aligned bounding box.")
    open: bool | None = Field(default=None, description="Open state; None when not openable.")
    held: bool = Field(default=False, description="True while the robot holds it.")


class RegionNode(_Model):
    """A region: a connected component of the door-cut Voronoi graph (a room or part of one)."""

    id: str = Field(description="Readable id 'region_<k>', stable across steps where possible.")
    room_label: str | None = Field(default=None, description="Room type given later by the LLM, e.g. 'kitchen'.")
    centroid: Vec2 = Field(description="Mean position of its Voronoi nodes, metres.")
    nav_nodes: list[int] = Field(description="Indices of its nodes in SceneGraph.nav.")
    frontiers: list[Vec2] = Field(description="Frontier points (unexplored areas) attached to it, metres.")


class Relation(_Model):
    """A spatial relation derived from geometry: subject <predicate> object."""

    subject: str = Field(description="Object id of the contained / supported object.")
    predicate: vocabulary.Relation = Field(description="Relation type.")
    object: str = Field(description="Object id of the container / support.")


class RobotNode(_Model):
    """The robot's pose as the scene graph sees it (what it holds: ``SceneGraph.held_object``)."""

    position: Vec2 = Field(description="(x, y) in metres.")
    region_id: str | None = Field(description="Region of the Voronoi node closest to the robot.")


class NavGraphData(_Model):
    """Sparse Voronoi graph of the robot's navigable component (door edges included)."""

    node_xy: FloatArray = Field(description="(n, 2) node positions, metres.")
    edges: IntArray = Field(description="(m, 2) node index pairs.")
    weights: FloatArray = Field(description="(m,) edge lengths, metres.")
    door_edges: BoolArray = Field(description="(m,) True where the edge crosses an observed door.")
    node_region: list[str | None] = Field(description="Region id per node (None in doorways).")


class OccupancyMap(_Model):
    """BEV occupancy for A*: 0 unknown, 1 free, 2 occupied; ``grid[ix, iy]`` on the ``frame`` Grid."""

    grid: IntArray = Field(description="(nx, ny) cell values.")
    origin_xy: Vec2 = Field(description="World position of the grid's corner, metres.")
    resolution_m: float = Field(description="Cell size, metres.")

    @property
    def frame(self) -> Grid:
        """The :class:`~more_agent.sim.grid.Grid` that ``grid`` lies on."""
        return Grid(origin_xy=self.origin_xy, resolution_m=self.resolution_m)


class SceneGraph(_Model):
    """The hierarchical scene graph of one high-level step."""

    schema_version: int = Field(default=SCHEMA_VERSION, description="JSON schema version.")
    step: int = Field(description="Index of the build that produced it (0-based).")
    robot: RobotNode = Field(description="Robot pose and region.")
    regions: dict[str, RegionNode] = Field(description="Regions by id, reachable from the robot.")
    objects: dict[str, ObjectNode] = Field(description="Objects by id (in reachable regions, or held).")
    relations: list[Relation] = Field(description="Spatial relations between objects.")
    nav: NavGraphData = Field(description="Sparse Voronoi navigation graph.")
    occupancy: OccupancyMap | None = Field(default=None, exclude=True, description="BEV grid (not in JSON).")
    _tree: cKDTree | None = PrivateAttr(default=None)

    def closest_node(self, xy: Vec2) -> int:
        """Index of the navigation node closest to ``xy``; raises ValueError on an empty graph."""
        if len(self.nav.node_xy) == 0:
            raise ValueError("the navigation graph is empty")
        if self._tree is None:
            self._tree = cKDTree(self.nav.node_xy)
        return int(self._tree.query(np.asarray(xy, dtype=float))[1])

    @model_validator(mode="after")
    def _check_hierarchy(self) -> SceneGraph:
        held = [o.id for o in self.objects.values() if o.held]
        if len(held) > 1:
            raise ValueError(f"the robot holds one object at most, not {held}")
        for o in self.objects.values():
            if o.held != (o.region_id is None) or not (o.held or o.region_id in self.regions):
                raise ValueError(
                    f"object {o.id!r}: held={o.held} with region {o.region_id!r}; a held object has "
                    "no region, any other one a region of the graph"
                )
        return self

    def objects_in(self, region_id: str) -> list[ObjectNode]:
        """Objects of one region, sorted by id (unknown region ids raise KeyError)."""
        if region_id not in self.regions:
            raise KeyError(region_id)
        return sorted((o for o in self.objects.values() if o.region_id == region_id), key=lambda o: o.id)

    def frontiers(self, region_id: str) -> list[Vec2]:
        """Frontier points of one region (for explore(room))."""
        return list(self.regions[region_id].frontiers)

    @property
    def held_object(self) -> ObjectNode | None:
        """The object in the robot's hand, if any."""
        return next((o for o in self.objects.values() if o.held), None)

    def without_room_labels(self, region_ids: Iterable[str]) -> SceneGraph:
        """A copy with the room labels of the given regions taken away (to be typed again; unknown ids raise KeyError)."""
        regions = dict(self.regions)
        for rid in region_ids:
            regions[rid] = regions[rid].model_copy(update={"room_label": None})
        return self.model_copy(update={"regions": regions})

    def with_room_labels(self, labels: dict[str, str]) -> SceneGraph:
        """A copy with LLM room labels set on the given regions (unknown ids raise KeyError)."""
        regions = dict(self.regions)
        for rid, label in labels.items():
            regions[rid] = regions[rid].model_copy(update={"room_label": label})
        return self.model_copy(update={"regions": regions})
