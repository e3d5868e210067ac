"""``compare_graphs``: how far two scene graphs of the same scene differ, whatever their region ids
(a bag's round trip, a Spark-DSG round trip)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from more_agent.scene_graph import SceneGraph


@dataclass(frozen=True)
class GraphDifference:
    """What differs between graph ``a`` and graph ``b``."""

    only_in_a: list[str]
    """Object ids of ``a`` missing from ``b``."""
    only_in_b: list[str]
    attribute_mismatches: list[str]
    """Objects in both whose category, open state or held flag differ."""
    same_regions: bool
    """Both split their objects into the same groups (the same regions, ids aside) and have as many regions."""
    max_position_error_m: float
    """Largest distance between an object's centres in ``a`` and ``b`` (0 when none in common)."""
    max_box_error_m: float
    """Largest difference of a bounding-box corner coordinate."""
    max_centroid_error_m: float
    """Largest distance from a region's centroid in ``a`` to the nearest region centroid of ``b``."""

    def same_within(self, tol_m: float) -> bool:
        """Same objects, attributes and regions, every position and box corner within ``tol_m``."""
        return (
            not self.only_in_a
            and not self.only_in_b
            and not self.attribute_mismatches
            and self.same_regions
            and max(self.max_position_error_m, self.max_box_error_m) <= tol_m
        )


def _groups(graph: SceneGraph) -> set[frozenset[str]]:
    return {frozenset(o.id for o in graph.objects_in(rid)) for rid in graph.regions}


def compare_graphs(a: SceneGraph, b: SceneGraph) -> GraphDifference:
    """Objects matched by id, regions by the objects they hold (see :class:`GraphDifference`)."""
    common = sorted(set(a.objects) & set(b.objects))
    mismatched = [
        i
        for i in common
        if (a.objects[i].category, a.objects[i].open, a.objects[i].held)
        != (b.objects[i].category, b.objects[i].open, b.objects[i].held)
    ]
    pos = [np.linalg.norm(np.subtract(a.objects[i].position, b.objects[i].position)) for i in common]
    box = [
        np.abs(
            np.subtract((a.objects[i].bbox.min, a.objects[i].bbox.max), (b.objects[i].bbox.min, b.objects[i].bbox.max))
        ).max()
        for i in common
    ]
    centroids_b = np.array([r.centroid for r in b.regions.values()]).reshape(-1, 2)
    cen = (
        [np.linalg.norm(centroids_b - r.centroid, axis=1).min() for r in a.regions.values()] if len(centroids_b) else []
    )
    return GraphDifference(
        only_in_a=sorted(set(a.objects) - set(b.objects)),
        only_in_b=sorted(set(b.objects) - set(a.objects)),
        attribute_mismatches=mismatched,
        same_regions=len(a.regions) == len(b.regions) and _groups(a) == _groups(b),
        max_position_error_m=float(max(pos, default=0.0)),
        max_box_error_m=float(max(box, default=0.0)),
        max_centroid_error_m=float(max(cen, default=0.0 if not a.regions else np.inf)),
    )
