"""MORE's scene graph <-> Spark-DSG's ``DynamicSceneGraph`` (Hydra's scene graphs), both ways.

Export (``to_spark_dsg``, ``save_spark_dsg``): objects -> OBJECTS (2), the sparse Voronoi nodes -> PLACES
(3, their edges weighted by length), regions -> ROOMS (4); room -> place and place -> object (the
nearest place of the object's region) edges as Hydra links them; spatial relations as object -> object
edges. What Spark-DSG has no field for (instance label, open / held, door edges, frontiers, the robot)
goes into the nodes', edges' and graph's metadata under ``more_agent``, so a round trip is lossless.
Files: ``.json`` (Spark-DSG's JSON), ``.sparkdsg`` / ``.bson`` (its binary formats).

Import (``from_spark_dsg``, ``load_spark_dsg``), for graphs as Hydra writes them: an object's category
is, in order, our metadata, the user's label map (semantic label -> name), the graph's OBJECTS label
space; places become the navigation graph (edge weights as given, else the places' distance), rooms the regions;
a place without a room joins the room closest along the place graph, and places no room reaches form a region
per connected component; an object's region is
its parent room, its parent place's, else the nearest place's. Relations come from our metadata, else from
the boxes (``scene_graph.relations``, within each region). Frontier places (Hydra's ``real_place = False``) become frontiers.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np
from pydantic import ValidationError

from more_agent.errors import UserError
from more_agent.interop.ingest import letters
from more_agent.interop.requirement import require
from more_agent.scene_graph import SceneGraph
from more_agent.scene_graph.model import Box3D, NavGraphData, ObjectNode, RegionNode, Relation, RobotNode
from more_agent.scene_graph.relations import spatial_relations

OBJECTS, PLACES, ROOMS = 2, 3, 4
"""Spark-DSG layer ids."""
SUFFIXES = (".json", ".sparkdsg", ".bson")
"""File suffixes Spark-DSG saves and loads."""
KEY = "more_agent"
"""Metadata key of what Spark-DSG has no field for."""
RELATION_TOL_M, INSIDE_FRACTION = 0.08, 0.7
"""Geometric relations of imported graphs (``MappingConfig`` defaults)."""


class SparkDsgError(UserError):
    """A Spark-DSG graph MORE cannot use (the message says which node and what to pass)."""


def _dsg() -> Any:
    return require("spark_dsg", "spark-dsg")


# ------------------------------------------------------------------------------------- export
def to_spark_dsg(graph: SceneGraph) -> Any:
    """A ``spark_dsg.DynamicSceneGraph`` of ``graph`` (module docstring)."""
    dsg = _dsg()
    G = dsg.DynamicSceneGraph()
    categories = sorted({o.category for o in graph.objects.values()})
    G.set_labelspace(dsg.Labelspace(dict(enumerate(categories))), OBJECTS)
    places = [dsg.NodeSymbol("p", i) for i in range(len(graph.nav.node_xy))]
    for sym, xy, place_region in zip(places, graph.nav.node_xy.tolist(), graph.nav.node_region):
        attrs = dsg.PlaceNodeAttributes()
        attrs.position = np.array([xy[0], xy[1], 0.0])
        attrs.real_place = True
        attrs.metadata.set({KEY: {"region": place_region}})
        G.add_node(PLACES, sym, attrs)
    for k, ((a, b), w, door) in enumerate(
        zip(graph.nav.edges.tolist(), graph.nav.weights.tolist(), graph.nav.door_edges.tolist())
    ):
        G.insert_edge(places[a], places[b], _edge(dsg, weight=w, door=bool(door), order=k))
    rooms = {}
    for k, (rid, region) in enumerate(sorted(graph.regions.items())):
        attrs = dsg.RoomNodeAttributes()
        attrs.position = np.array([*region.centroid, 0.0])
        attrs.name = region.room_label or rid
        attrs.metadata.set(
            {KEY: {"region_id": rid, "room_label": region.room_label, "frontiers": [list(f) for f in region.frontiers]}}
        )
        rooms[rid] = dsg.NodeSymbol("R", k)
        G.add_node(ROOMS, rooms[rid], attrs)
        for i in region.nav_nodes:
            G.insert_edge(rooms[rid], places[i])
    symbols = {}
    for k, obj in enumerate(sorted(graph.objects.values(), key=lambda o: o.id)):
        symbols[obj.id] = dsg.NodeSymbol("O", k)
        G.add_node(OBJECTS, symbols[obj.id], _object_attrs(dsg, obj, categories.index(obj.category)))
        if obj.region_id is not None and graph.regions[obj.region_id].nav_nodes:
            nodes = graph.regions[obj.region_id].nav_nodes
            near = nodes[int(np.argmin(np.linalg.norm(graph.nav.node_xy[nodes] - obj.position[:2], axis=1)))]
            G.insert_edge(places[near], symbols[obj.id])
    for k, rel in enumerate(graph.relations):
        G.insert_edge(
            symbols[rel.subject],
            symbols[rel.object],
            _edge(dsg, relation=[rel.subject, rel.predicate, rel.object], order=k),
        )
    G.metadata.add({KEY: {"step": graph.step, "robot": graph.robot.model_dump()}})
    return G


def _edge(dsg: Any, weight: float | None = None, **meta: Any) -> Any:
    e = dsg.EdgeAttributes()
    if weight is not None:
        e.weight, e.weighted = weight, True
    e.metadata.set({KEY: meta})
    return e


def _object_attrs(dsg: Any, obj: ObjectNode, label: int) -> Any:
    attrs = dsg.ObjectNodeAttributes()
    lo, hi = np.array(obj.bbox.min), np.array(obj.bbox.max)
    attrs.position = np.array(obj.position)
    attrs.bounding_box = dsg.BoundingBox((hi - lo).astype(np.float32), ((lo + hi) / 2).astype(np.float32))
    attrs.semantic_label = label
    attrs.name = obj.label
    attrs.metadata.set(
        {
            KEY: {
                "id": obj.id,
                "category": obj.category,
                "instance_id": obj.instance_id,
                "label": obj.label,
                "open": obj.open,
                "held": obj.held,
                "bbox": [list(obj.bbox.min), list(obj.bbox.max)],
            }
        }
    )
    return attrs


def save_spark_dsg(graph: SceneGraph, path: Path) -> None:
    """Write ``graph`` in Spark-DSG's JSON (``.json``) or binary format (``.sparkdsg``, ``.bson``)."""
    if Path(path).suffix not in SUFFIXES:
        raise SparkDsgError(f"{path}: Spark-DSG files end in {', '.join(SUFFIXES)}")
    to_spark_dsg(graph).save(str(path), include_mesh=False)


# ------------------------------------------------------------------------------------- import
def load_spark_dsg(path: Path, label_map: Mapping[int, str] | None = None) -> SceneGraph:
    """Read a Spark-DSG file (JSON or binary) into MORE's scene graph (``from_spark_dsg``)."""
    dsg = _dsg()
    try:
        with _stdout_to_stderr():
            G = dsg.DynamicSceneGraph.load(str(path))
    except Exception as e:  # noqa: BLE001 - the bindings raise RuntimeError / ValueError for bad files
        raise SparkDsgError(f"cannot read {path} as a Spark-DSG graph: {type(e).__name__}: {e}") from None
    try:
        return from_spark_dsg(G, label_map)
    except ValidationError as e:
        raise SparkDsgError(f"{path}: the graph does not make a MORE scene graph: {str(e).splitlines()[0]}") from None


@contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """Send what the C++ library prints (warnings about old encodings) to stderr: stdout may carry JSON."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _meta(attrs: Any) -> dict[str, Any]:
    return dict(attrs.metadata.get().get(KEY) or {})


def _labelspace(G: Any, layer: int, name: str) -> dict[int, str]:
    """The layer's label space from the graph's metadata (as spark-dsg saves it, by layer name or key)."""
    spaces = G.metadata.get().get("labelspaces") or {}
    pairs: Any = next((spaces[k] for k in (name, f"_l{layer}p0", str(layer)) if k in spaces), [])
    return {int(k): str(v) for k, v in (pairs.items() if isinstance(pairs, dict) else pairs)}


def from_spark_dsg(G: Any, label_map: Mapping[int, str] | None = None) -> SceneGraph:
    """MORE's scene graph of a ``DynamicSceneGraph`` (module docstring)."""
    place_nodes = [n for n in G.get_layer(PLACES).nodes] if G.has_layer(PLACES) else []
    real = [n for n in place_nodes if getattr(n.attributes, "real_place", True)]
    index = {n.id.value: i for i, n in enumerate(real)}
    xy = np.array([n.attributes.position[:2] for n in real], dtype=float).reshape(-1, 2)
    edges, given, doors = [], [], []
    metas = [(e, _meta(e.info)) for e in (G.get_layer(PLACES).edges if place_nodes else [])]
    for e, meta in sorted(metas, key=lambda em: em[1].get("order", 0)):
        if e.source in index and e.target in index:
            edges.append((index[e.source], index[e.target]))
            given.append(float(e.info.weight) if e.info.weighted else np.nan)
            doors.append(bool(meta.get("door", False)))
    pairs = np.array(edges, dtype=np.int64).reshape(-1, 2)
    lengths = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    weights = np.where(np.isnan(given), lengths, given) if edges else lengths
    node_region, regions = _regions(G, real, xy, pairs, lengths)
    objects = _objects(G, label_map, real, index, xy, node_region)
    relations = _relations(G, objects)
    frontiers = [n.attributes.position[:2] for n in place_nodes if not getattr(n.attributes, "real_place", True)]
    regions = _with_frontiers(regions, frontiers, xy, node_region)
    robot = _robot(G, xy, node_region)
    return SceneGraph(
        step=int((G.metadata.get().get(KEY) or {}).get("step", 0)),
        robot=robot,
        regions=regions,
        objects=objects,
        relations=relations,
        nav=NavGraphData(node_xy=xy, edges=pairs, weights=weights, door_edges=doors, node_region=node_region),
    )


def _parent_in(node: Any, layer_nodes: Mapping[int, Any]) -> Any:
    return next((layer_nodes[p] for p in node.parents() if p in layer_nodes), None) if node.has_parent() else None


def _regions(
    G: Any, real: list[Any], xy: np.ndarray, edges: np.ndarray, lengths: np.ndarray
) -> tuple[list[str | None], dict[str, RegionNode]]:
    """Region id per place and the regions: rooms, then one per component of room-less places."""
    rooms = {n.id.value: n for n in G.get_layer(ROOMS).nodes} if G.has_layer(ROOMS) else {}
    names, room_labels, frontiers = {}, {}, {}
    room_space = _labelspace(G, ROOMS, "ROOMS")
    for k, (value, node) in enumerate(sorted(rooms.items())):
        meta = _meta(node.attributes)
        names[value] = meta.get("region_id") or f"region_{k}"
        room_labels[names[value]] = meta.get("room_label", room_space.get(node.attributes.semantic_label))
        frontiers[names[value]] = [tuple(f) for f in meta.get("frontiers", [])]
    node_region: list[str | None] = []
    for n in real:
        room = _parent_in(n, rooms)
        node_region.append(names[room.id.value] if room is not None else None)
    places = nx.Graph()
    places.add_nodes_from(range(len(real)))
    places.add_weighted_edges_from(zip(edges[:, 0].tolist(), edges[:, 1].tolist(), lengths.tolist()))
    roomed = {i for i, r in enumerate(node_region) if r is not None}
    if roomed:  # a room-less place joins the room it is closest to along the place graph
        _, paths = nx.multi_source_dijkstra(places, roomed)
        for i, path in paths.items():
            node_region[i] = node_region[path[0]]
    loose = places.subgraph(i for i, r in enumerate(node_region) if r is None)
    for k, comp in enumerate(sorted(nx.connected_components(loose), key=min)):
        for i in comp:
            node_region[i] = f"region_{len(rooms) + k}"
    members: dict[str, list[int]] = {rid: [] for rid in names.values()}
    for i, rid in enumerate(node_region):
        assert rid is not None  # every place has a region by now
        members.setdefault(rid, []).append(i)
    room_of = {rid: rooms[v] for v, rid in names.items()}
    regions = {}
    for rid in sorted(members):
        mine = members[rid]
        centroid = xy[mine].mean(0) if mine else np.asarray(room_of[rid].attributes.position[:2])
        regions[rid] = RegionNode(
            id=rid,
            room_label=room_labels.get(rid),
            centroid=tuple(map(float, centroid)),
            nav_nodes=mine,
            frontiers=frontiers.get(rid, []),
        )
    return node_region, regions


def _objects(
    G: Any,
    label_map: Mapping[int, str] | None,
    real: list[Any],
    index: dict[int, int],
    xy: np.ndarray,
    node_region: list[str | None],
) -> dict[str, ObjectNode]:
    nodes = [n for n in G.get_layer(OBJECTS).nodes] if G.has_layer(OBJECTS) else []
    space = {**_labelspace(G, OBJECTS, "OBJECTS"), **(label_map or {})}
    rooms = {n.id.value: n for n in G.get_layer(ROOMS).nodes} if G.has_layer(ROOMS) else {}
    per_category: dict[str, int] = {}
    out: dict[str, ObjectNode] = {}
    for n in sorted(nodes, key=lambda n: n.id.value):
        a, meta = n.attributes, _meta(n.attributes)
        category = meta.get("category") or space.get(int(a.semantic_label))
        if category is None:
            raise SparkDsgError(
                f"object node {n.id} has semantic label {a.semantic_label}, which neither the graph's "
                "OBJECTS label space nor the label map names; pass --label-map FILE (JSON {label: name})"
            )
        k = per_category.get(category, 0)
        per_category[category] = k + 1
        label = meta.get("label") or f"{category} {letters(k)}"
        held = bool(meta.get("held", False))
        region = None if held else _object_region(n, a, rooms, real, index, xy, node_region)
        if meta.get("bbox"):
            lo, hi = meta["bbox"]
        else:
            box = a.bounding_box
            lo, hi = list(map(float, box.min)), list(map(float, box.max))
        if region is None and not held:
            continue  # no place to hang it on: a graph without places
        out[meta.get("id") or label] = ObjectNode(
            id=meta.get("id") or label,
            category=category,
            instance_id=int(meta.get("instance_id", n.id.category_id)),
            label=label,
            region_id=region,
            position=tuple(map(float, a.position)),
            bbox=Box3D(min=lo, max=hi),
            open=meta.get("open"),
            held=held,
        )
    return out


def _object_region(
    node: Any,
    attrs: Any,
    rooms: Mapping[int, Any],
    real: list[Any],
    index: dict[int, int],
    xy: np.ndarray,
    node_region: list[str | None],
) -> str | None:
    """Its parent place's region, else its parent room's, else the nearest place's."""
    for p in node.parents() if node.has_parent() else []:
        if p in index:
            return node_region[index[p]]
        if p in rooms:
            meta = _meta(rooms[p].attributes)
            return meta.get("region_id") or f"region_{sorted(rooms).index(p)}"
    if len(xy) == 0:
        return None
    return node_region[int(np.argmin(np.linalg.norm(xy - np.asarray(attrs.position[:2]), axis=1)))]


def _relations(G: Any, objects: dict[str, ObjectNode]) -> list[Relation]:
    """Our relations from the object edges' metadata; from the boxes when the graph has none of ours."""
    metas = [_meta(e.info) for e in G.get_layer(OBJECTS).edges] if G.has_layer(OBJECTS) else []
    ours = sorted((m.get("order", 0), m["relation"]) for m in metas if m.get("relation"))
    if ours:
        return [Relation(subject=s, predicate=p, object=o) for _, (s, p, o) in ours if s in objects and o in objects]
    by_region: dict[str | None, list[ObjectNode]] = {}
    for o in objects.values():
        if not o.held and o.category != "door":
            by_region.setdefault(o.region_id, []).append(o)
    relations = []
    for placed in by_region.values():  # per region: the pairs test is quadratic, and relations stay within rooms
        lo = np.array([o.bbox.min for o in placed]).reshape(-1, 3)
        hi = np.array([o.bbox.max for o in placed]).reshape(-1, 3)
        relations += [
            Relation(subject=placed[a].id, predicate=p, object=placed[b].id)
            for a, p, b in spatial_relations(lo, hi, tol_m=RELATION_TOL_M, inside_fraction=INSIDE_FRACTION)
        ]
    return relations


def _with_frontiers(
    regions: dict[str, RegionNode], frontiers: list[Any], xy: np.ndarray, node_region: list[str | None]
) -> dict[str, RegionNode]:
    """Regions with our frontiers (from metadata) or Hydra's frontier places, at the nearest place's region."""
    extra: dict[str, list[tuple[float, float]]] = {}
    for f in frontiers:
        if len(xy):
            rid = node_region[int(np.argmin(np.linalg.norm(xy - np.asarray(f), axis=1)))]
            extra.setdefault(rid or "", []).append((float(f[0]), float(f[1])))
    return {rid: r.model_copy(update={"frontiers": r.frontiers + extra.get(rid, [])}) for rid, r in regions.items()}


def _robot(G: Any, xy: np.ndarray, node_region: list[str | None]) -> RobotNode:
    """Our robot metadata, else the last agent pose, else the first place."""
    meta = (G.metadata.get().get(KEY) or {}).get("robot")
    if meta:
        return RobotNode.model_validate(meta)
    agents = [n for n in G.nodes if isinstance(n.attributes, _dsg().AgentNodeAttributes)]
    position = agents[-1].attributes.position[:2] if agents else xy[0] if len(xy) else (0.0, 0.0)
    region = node_region[int(np.argmin(np.linalg.norm(xy - np.asarray(position), axis=1)))] if len(xy) else None
    return RobotNode(position=(float(position[0]), float(position[1])), region_id=region)
