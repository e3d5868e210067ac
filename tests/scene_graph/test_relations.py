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


def test_the_smallest_container_and_the_highest_support_win_and_ties_go_to_the_first_listed():
    """An apple in a bowl in a cabinet is in the bowl; a mug whose bottom lies within the tolerance of two
    tops stands on the higher; of two equal boxes that both hold a pen, the one listed first holds it."""
    mins = np.array(
        [[0, 0, 0], [0.1, 0.1, 0.1], [0.2, 0.2, 0.15], [2, 0, 0], [2, 0, 0.05], [2.1, 0.1, 0.83],
         [4, 0, 0], [4, 0, 0], [4.1, 0.1, 0.1]], float)
    maxs = np.array(
        [[1, 1, 1], [0.6, 0.6, 0.4], [0.3, 0.3, 0.25], [3, 1, 0.8], [3, 1, 0.85], [2.2, 0.2, 0.95],
         [5, 1, 1], [5, 1, 1], [4.2, 0.2, 0.3]], float)
    rels = spatial_relations(mins, maxs)
    assert (2, "inside", 1) in rels  # the apple: the bowl, not the cabinet
    assert (1, "inside", 0) in rels
    assert (5, "ontop", 4) in rels  # the mug: the higher of two tops it touches
    assert (8, "inside", 6) in rels  # the pen: the first of two equal boxes
