"""Spatial relations from boxes."""

import numpy as np

from more_agent.scene_graph import spatial_relations


def test_inside_ontop_and_none() -> None:
    mins = np.array([[0, 0, 0], [0.2, 0.2, 0.1], [0, 0, 0.8], [2, 2, 0], [1.0, 0.0, 0.8]], float)
    maxs = np.array([[1, 1, 0.8], [0.4, 0.4, 0.3], [0.2, 0.2, 0.9], [3, 3, 1], [1.3, 0.3, 0.9]], float)
    rels = spatial_relations(mins, maxs, tol_m=0.05)
    assert (1, "inside", 0) in rels
    assert (2, "ontop", 0) in rels
    assert not any(a == 4 for a, _, _ in rels)  # overhangs the cabinet by 100 %: no support
    assert not any(a in (0, 3) for a, _, _ in rels)
    assert spatial_relations(mins[:1], maxs[:1]) == []


def test_flat_item_sharing_the_tables_top_voxel_is_ontop_not_inside():
    # A plate on a table: after voxelisation (7.5 cm) both boxes end in the same top voxel.
    mins = np.array([[0.0, 0.0, 0.0], [0.4, 0.4, 0.75]])
    maxs = np.array([[1.2, 0.8, 0.825], [0.6, 0.6, 0.825]])
    assert spatial_relations(mins, maxs) == [(1, "ontop", 0)]
