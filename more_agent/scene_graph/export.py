"""Scene-graph export: versioned JSON loading and a networkx view of the hierarchy."""

from __future__ import annotations

import json

import networkx as nx

from more_agent.scene_graph.model import SCHEMA_VERSION, Layer, SceneGraph

ROOT_ID = "root"


def load_scene_graph(text: str) -> SceneGraph:
    """Parse JSON written by ``SceneGraph.model_dump_json``; a different schema version raises
    ValueError. The occupancy grid is not part of JSON and comes back as None."""
    data = json.loads(text)
    version = data.get("schema_version")
    if version != SCHEMA_VERSION:
        raise ValueError(f"scene graph schema version {version!r} is not the supported {SCHEMA_VERSION}")
    return SceneGraph.model_validate(data)


def to_networkx(graph: SceneGraph, *, include_nav: bool = False) -> nx.DiGraph:
    """Directed graph: root -> regions -> objects ('contains' edges), object -> object edges for
    spatial relations ('inside' / 'ontop'); nodes carry ``layer`` and their attributes.
    ``include_nav`` adds the Voronoi nodes ('nav_<i>', layer 'nav') with undirected-as-two-way
    'nav' edges and region -> nav 'covers' edges."""
    g = nx.DiGraph()
    g.add_node(ROOT_ID, layer=Layer.ROOT.value, robot=graph.robot.model_dump())
    for rid, region in graph.regions.items():
        g.add_node(rid, layer=Layer.REGION.value, **region.model_dump(exclude={"id", "nav_nodes"}))
        g.add_edge(ROOT_ID, rid, kind="contains")
    for oid, obj in graph.objects.items():
        g.add_node(oid, layer=Layer.OBJECT.value, **obj.model_dump(exclude={"id"}))
        g.add_edge(obj.region_id or ROOT_ID, oid, kind="contains")
    for rel in graph.relations:
        g.add_edge(rel.subject, rel.object, kind=rel.predicate)
    if include_nav:
        for i, xy in enumerate(graph.nav.node_xy.tolist()):
            g.add_node(f"nav_{i}", layer="nav", xy=tuple(xy))
            region_id = graph.nav.node_region[i]
            if region_id is not None:
                g.add_edge(region_id, f"nav_{i}", kind="covers")
        for (a, b), w in zip(graph.nav.edges.tolist(), graph.nav.weights.tolist()):
            g.add_edge(f"nav_{a}", f"nav_{b}", kind="nav", weight=w)
            g.add_edge(f"nav_{b}", f"nav_{a}", kind="nav", weight=w)
    return g
