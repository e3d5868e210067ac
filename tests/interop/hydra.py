"""Spark-DSG graphs as Hydra writes them, built through spark-dsg's own API (no MORE metadata), and the
public Hydra output shipped as a fixture (Spark-DSG's python/tests/resources/apartment_dsg.json, BSD
licence in tests/fixtures/hydra/LICENSE.spark-dsg)."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import spark_dsg as dsg

APARTMENT = Path(__file__).parents[1] / "fixtures" / "hydra" / "apartment_dsg.json.gz"
APARTMENT_LABELS = {5: "chair", 11: "lamp", 16: "table"}
"""The labels of its objects in Hydra's uhumans2_apartment label space (config/label_spaces)."""
KITCHEN_LABELS = {0: "table", 1: "cup", 2: "fridge", 3: "chair"}


def apartment(tmp_path: Path) -> Path:
    """The shipped Hydra graph, unpacked (spark-dsg loads files only)."""
    path = tmp_path / "apartment_dsg.json"
    path.write_bytes(gzip.decompress(APARTMENT.read_bytes()))
    return path


def _node(G, layer: int, key: str, index: int, attrs, position) -> object:
    attrs.position = np.asarray(position, dtype=float)
    G.add_node(layer, dsg.NodeSymbol(key, index), attrs)
    return dsg.NodeSymbol(key, index)


def _object(G, index: int, label: int, lo, hi, parent) -> None:
    attrs = dsg.ObjectNodeAttributes()
    attrs.semantic_label = label
    lo, hi = np.asarray(lo, dtype=np.float32), np.asarray(hi, dtype=np.float32)
    attrs.bounding_box = dsg.BoundingBox(hi - lo, (lo + hi) / 2)
    sym = _node(G, dsg.DsgLayers.OBJECTS, "O", index, attrs, (lo + hi) / 2)
    if parent is not None:
        G.insert_edge(parent, sym)


def kitchen_and_hall(*, labelspace: bool = True):
    """Two rooms: R0 (places p0-p2) with a table, a cup on it and a chair; R1 (p3, p4) with a fridge
    hanging on the room itself; p5 has no room but hangs off p4; p6 is a frontier place (not real)."""
    G = dsg.DynamicSceneGraph()
    places = []
    for i, xy in enumerate([(0, 0), (1, 0), (2, 0), (4, 0), (5, 0), (6, 0)]):
        attrs = dsg.PlaceNodeAttributes()
        attrs.distance, attrs.real_place = 0.5, True
        places.append(_node(G, dsg.DsgLayers.PLACES, "p", i, attrs, (*xy, 0.0)))
    frontier = dsg.PlaceNodeAttributes()
    frontier.real_place = False
    _node(G, dsg.DsgLayers.PLACES, "p", 6, frontier, (7.0, 1.0, 0.0))
    for a, b in [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5)]:
        G.insert_edge(places[a], places[b])
    rooms = [_node(G, dsg.DsgLayers.ROOMS, "R", k, dsg.RoomNodeAttributes(), (x, 0.0, 0.0)) for k, x in enumerate((1.0, 4.5))]
    for room, members in ((rooms[0], places[:3]), (rooms[1], places[3:5])):
        for p in members:
            G.insert_edge(room, p)
    _object(G, 0, 0, (0.6, -0.4, 0.0), (1.4, 0.4, 0.75), places[1])  # table
    _object(G, 1, 1, (0.9, -0.05, 0.75), (1.0, 0.05, 0.85), places[1])  # cup on the table
    _object(G, 2, 3, (1.8, 0.3, 0.0), (2.2, 0.7, 0.9), places[2])  # chair
    _object(G, 3, 2, (4.6, 0.5, 0.0), (5.4, 1.2, 1.8), rooms[1])  # fridge
    if labelspace:
        G.set_labelspace(dsg.Labelspace(KITCHEN_LABELS), dsg.DsgLayers.OBJECTS)
    return G
