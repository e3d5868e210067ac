"""Hierarchical scene graph (root / regions / objects): typed data model, incremental builder from
posed RGB-D + semantic frames, spatial relations, and JSON / networkx export."""

from more_agent.robot import InstanceInfo
from more_agent.scene_graph.builder import SceneGraphBuilder
from more_agent.scene_graph.export import load_scene_graph, to_networkx
from more_agent.scene_graph.model import (
    SCHEMA_VERSION,
    Box3D,
    Layer,
    NavGraphData,
    ObjectNode,
    OccupancyMap,
    RegionNode,
    Relation,
    RobotNode,
    SceneGraph,
)
from more_agent.scene_graph.relations import spatial_relations

__all__ = [
    "SCHEMA_VERSION",
    "Box3D",
    "InstanceInfo",
    "Layer",
    "NavGraphData",
    "ObjectNode",
    "OccupancyMap",
    "RegionNode",
    "Relation",
    "RobotNode",
    "SceneGraph",
    "SceneGraphBuilder",
    "load_scene_graph",
    "spatial_relations",
    "to_networkx",
]
