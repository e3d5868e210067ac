"""``SceneGraphBuilder``: fuses frames incrementally and builds a ``SceneGraph`` per high-level step.

``integrate`` (every frame) only updates the voxel map and per-instance bookkeeping (attributes,
viewpoints, what rides on the held object). ``build`` (once per step) runs the graph pipeline
``mapping.region_graph`` on the BEV (Voronoi graph -> sparsification -> door cuts -> regions
(+ sub-region merging) -> Eq. 1 object assignment -> frontiers), then gives regions stable ids,
reduces everything to the robot's navigable component and adds the spatial relations (as perceived
where the instance information says how an object rests, from box geometry otherwise).

Region ids: each region keeps an anchor point; at the next build a region inherits the id of the
old anchor(s) whose nearest node (within ``2 * sparsify_threshold_m``) it contains, the smallest
id when several merge; regions without anchor get the next unused ``region_<k>``, in order of
their smallest (x, y) node. Anchors of regions that are out of reach are remembered, so a room
seen through a window keeps its id once a door opens. LLM room labels are set with
``set_room_labels`` and follow their region id in every later build (``SceneGraph.with_room_labels``
labels one graph only).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from more_agent.mapping import (
    FREE,
    OCCUPIED,
    MappingConfig,
    NavGraph,
    RegionGraph,
    VoxelMap,
    line_of_sight,
    region_graph,
)
from more_agent.robot import InstanceInfo
from more_agent.scene_graph.model import (
    Box3D,
    NavGraphData,
    ObjectNode,
    OccupancyMap,
    RegionNode,
    Relation,
    RobotNode,
    SceneGraph,
)
from more_agent.scene_graph.relations import spatial_relations
from more_agent.sim.grid import Grid
from more_agent.sim.scene import FREE_SPACE_CLASSES

STRUCTURE_CATEGORIES = ("wall", "window", "door")
"""Classes that block line of sight for object assignment."""

PATH_JOIN_M = 0.3
"""A graph component whose node a point of the robot's path sees within this distance is reachable (``build``)."""

GLIMPSE_MAX_PIXELS = 400
"""Instances covering at most this many pixels of a frame also get a box from those pixels (``_glimpse``)."""


class SceneGraphBuilder:
    """Incremental scene-graph builder over posed depth + semantic + instance frames."""

    def __init__(self, class_names: Sequence[str], config: MappingConfig | None = None) -> None:
        self.config = config or MappingConfig()
        cfg = self.config
        self.class_names = list(class_names)
        self.voxels = VoxelMap(
            free_class_ids=[i for i, n in enumerate(self.class_names) if n in FREE_SPACE_CLASSES],
            resolution_m=cfg.resolution_m,
            z_min_m=cfg.z_min_m,
            z_max_m=cfg.z_max_m,
            bev_max_height_m=cfg.bev_max_height_m,
            max_range_m=cfg.max_range_m,
            carve_stride_px=cfg.carve_stride_px,
            initial_extent_m=cfg.initial_extent_m,
        )
        self._structure_ids = np.array([i for i, n in enumerate(self.class_names) if n in STRUCTURE_CATEGORIES])
        self._instances: dict[int, InstanceInfo] = {}
        self._viewpoints: dict[int, dict[tuple[int, int], tuple[float, float]]] = {}
        self._boxes: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        """Boxes of instances the frames no longer show as they are: lifted out of the voxel map (held,
        carried, a door whose leaf swung: ``_lift``) or put down (``remember``). ``build`` reads them and keeps
        none of the boxes it works out, so the graph follows the frames, not when it was built."""
        self._remembered: set[int] = set()
        self._carried: set[int] = set()
        """Instances resting on or in the held one (directly or through others): they travel with it."""
        self._carried_current = False
        """Whether ``_carried`` follows from the instances as they are (``_pick_up_contents``)."""
        self._held: set[int] = set()
        """The instances held now (by what perception last said of each)."""
        self._glimpsed: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        """Instance id -> box of its pixels when last in view small (used while the voxel map has none of it)."""
        self._nodes: dict[int, tuple[tuple[object, ...], ObjectNode]] = {}
        """Instance id -> the node last built for it and what it was built from (``_object_node``)."""
        self._anchors: dict[str, np.ndarray] = {}
        self._next_region = 0
        self._room_labels: dict[str, str] = {}
        self._step = 0

    # ---------------------------------------------------------------- per frame
    def integrate(
        self,
        depth: np.ndarray,
        semantic: np.ndarray,
        instance: np.ndarray,
        K: np.ndarray,
        T_world_cam: np.ndarray,
        instances: Mapping[int, InstanceInfo],
        robot_xy: Sequence[float],
    ) -> None:
        """Fuse one frame and remember, for every instance in view, its attributes and the
        robot position it was seen from. A newly held instance leaves the voxel map, and so does a
        door whose open state changed: rays through an opening pass above the lower part of a leaf
        seen closed and never clear it, so the doorway would stay blocked (and the room behind
        unexplored) for good; the cleared cells become frontiers until the room behind is seen. The
        door itself stays in the graph at its last box, in its new state, until a frame shows it
        again (the robot that opened it knows it is open)."""
        for iid, info in instances.items():
            previous = self._instances.get(iid)
            if info.held and not (previous is not None and previous.held):
                self._lift(iid)
            if info.held:
                self._remembered.discard(iid)
                self._glimpsed.pop(iid, None)
            if (
                info.category == "door"
                and previous is not None
                and previous.open is not None
                and info.open != previous.open
            ):
                self._lift(iid)  # the leaf swung: what was seen of it no longer blocks, but the door is still
                if iid in self._boxes:  # there, in the state the robot knows, until seen again
                    self._remembered.add(iid)
            if previous is None or _carry_facts(info) != _carry_facts(previous):
                self._carried_current = False
            self._instances[iid] = info
            (self._held.add if info.held else self._held.discard)(iid)
        held_now = sorted(self._held)
        self._pick_up_contents(holding=bool(held_now))
        for iid in self._carried & set(self._boxes):  # with the robot, where this frame was taken
            lo, hi = self._boxes[iid]
            shift = np.array([robot_xy[0] - (lo[0] + hi[0]) / 2, robot_xy[1] - (lo[1] + hi[1]) / 2, 0.0])
            self._boxes[iid] = (lo + shift, hi + shift)
        held = held_now + sorted(self._carried)
        self.voxels.integrate(depth, semantic, instance, K, T_world_cam, ignore_instances=held)
        hits = np.flatnonzero(np.isfinite(depth) & (instance > 0))  # the pixels that show an instance
        ids = instance.ravel()[hits]
        pixels = np.bincount(ids)  # per instance id
        self._glimpse(depth, hits, ids, pixels, K, T_world_cam, held)
        xy = (float(robot_xy[0]), float(robot_xy[1]))
        key = (round(xy[0] / self.config.viewpoint_spacing_m), round(xy[1] / self.config.viewpoint_spacing_m))
        for iid in np.flatnonzero(pixels).tolist():  # the instances in view
            self._viewpoints.setdefault(iid, {})[key] = xy

    def _pick_up_contents(self, *, holding: bool) -> None:
        """Update which instances ride on the held one (perception says what each rests on / in), when
        ``holding`` something. Newly carried ones leave the voxel map like the held one (seen in the
        robot's hand, they would map as an obstacle where the robot stands) and are kept in the graph,
        travelling with the robot. Skipped while what it reads (labels, supports, held) has not changed since it
        last ran holding something: it walks every instance known, and a store's robot knows hundreds."""
        if holding and self._carried_current:
            return
        self._carried_current = holding
        carried: set[int] = set()
        by_label = {info.label: iid for iid, info in self._instances.items()} if holding else {}
        for iid, info in self._instances.items() if holding else ():
            chain = info
            for _ in range(len(by_label)):  # up the supports, as far as the held object (cycles end it)
                support = by_label.get(chain.rests[1]) if chain.rests is not None and chain.rests[1] else None
                if support is None:
                    break
                chain = self._instances[support]
                if chain.held:
                    carried.add(iid)
                    break
        for iid in carried - self._carried:
            self._lift(iid)
            self._glimpsed.pop(iid, None)
            if iid in self._boxes:
                self._remembered.add(iid)
        self._carried = carried

    def _lift(self, iid: int) -> None:
        """Take ``iid`` out of the voxel map (it moves with the robot, or its leaf swung) and keep its box in
        ``_boxes``: that of the voxels it had, else of its last glimpse (a small item may show only as one),
        else the one kept before. What frames showed decides it, not when the graph was last built: a bag
        ingested builds once, the live robot every step (``build`` writes nothing here)."""
        removed = self.voxels.clear_instance(iid)
        if len(removed):
            self._boxes[iid] = self._voxel_box(removed)
        elif iid in self._glimpsed:
            self._boxes[iid] = self._glimpsed[iid]

    def remember(self, iid: int, box_min: Sequence[float] | np.ndarray, box_max: Sequence[float] | np.ndarray) -> None:
        """An instance the robot put down itself: kept in the graph with this box (world metres) while
        no frame shows it (e.g. deep in a basket), until it is held again."""
        self._boxes[iid] = (np.asarray(box_min, dtype=float), np.asarray(box_max, dtype=float))
        self._remembered.add(iid)

    def set_room_labels(self, labels: Mapping[str, str]) -> None:
        """Room labels (region id -> label) applied to this and every later build."""
        self._room_labels.update(labels)

    # ---------------------------------------------------------------- per step
    def build(self, robot_xy: Sequence[float], path_xy: Sequence[Sequence[float]] = ()) -> SceneGraph:
        """The scene graph of everything observed so far, reduced to the robot's component. It keeps no box
        it works out (from the voxels, a glimpse): the same frames give the same graph however often it is
        built (a bag's ingest builds once, the live robot every step); only region ids follow the builds.

        ``path_xy`` (the robot's path so far, oldest first) joins the components the robot can drive back
        to: it stood in them, and its path from there crosses nothing seen since (``_retraceable``). A
        pocket the graph cannot enter (a gap narrower than the graph's clearance that the robot
        squeezed through) then keeps the rest of the map instead of being all the robot knows.
        """
        grid = self.voxels.grid
        robot = np.asarray(robot_xy[:2], dtype=float)
        occ = self.voxels.occupancy()
        blocked = np.isin(self.voxels.top_class, self._structure_ids)
        voxels = self.voxels.instance_voxels()
        boxes = dict(self._boxes)  # what the builder keeps, under what this map shows: the build keeps no box
        boxes.update(self._voxel_boxes(voxels))
        for iid, box in self._glimpsed.items():
            if iid not in voxels and iid not in self._remembered:
                boxes[iid] = box
        known = sorted(i for i in set(voxels) | self._remembered | set(self._glimpsed) if i in self._instances)
        doors = [voxels[i][:, :2] for i in known if i in voxels and self._instances[i].category == "door"]
        objects = [i for i in known if not self._instances[i].held]
        centres = np.array([(boxes[i][0] + boxes[i][1]) / 2 for i in objects]).reshape(-1, 3)
        viewpoints = self._closest_viewpoints(objects, centres[:, :2])
        rg = region_graph(
            occ,
            grid,
            door_points=doors,
            objects_xy=centres[:, :2],
            viewpoints_xy=viewpoints,
            blocked=blocked,
            config=self.config,
        )
        region_ids = self._stable_ids(rg.graph, rg.labels)
        path = grid.passed(self._retraceable(path_xy, occ, grid))
        keep = self._robot_component(rg.graph, robot, blocked, grid, path)
        frontier_node = self._attach(rg.graph, rg.labels, rg.frontier_xy, blocked, grid)
        frontier_node = self._through_openings(rg.graph, rg.labels, keep, rg.frontier_xy, frontier_node, occ, grid)
        is_door = np.array([self._instances[i].category == "door" for i in objects], dtype=bool)
        assigned = self._within_reach(rg.graph, rg.labels, keep, centres[:, :2], rg.assigned, is_door, blocked, grid)
        return self._assemble(
            replace(rg, assigned=assigned), region_ids, keep, objects, boxes, frontier_node, robot, occ, grid
        )

    # ---------------------------------------------------------------- helpers
    def _glimpse(
        self,
        depth: np.ndarray,
        hits: np.ndarray,
        ids: np.ndarray,
        pixels: np.ndarray,
        K: np.ndarray,
        T_world_cam: np.ndarray,
        held: Sequence[int],
    ) -> None:
        """Box the small instances in view from their own pixels (``hits``: the flat indices of the pixels that show
        an instance, in reading order; ``ids``: its id at each; ``pixels``: how many each id has). A small item on
        a support shares its voxels with the support's surface (7.5 cm voxels, an egg is 5 cm tall), and the
        surface's hits overwrite it: without this the map loses it even while the robot looks at it."""
        small = (pixels > 0) & (pixels <= GLIMPSE_MAX_PIXELS)
        small[[i for i in held if i < small.size]] = False
        if not small.any():
            return
        take = small[ids]
        v, u = np.divmod(hits[take], depth.shape[1])
        d = depth[v, u].astype(float)
        cam = np.stack([(u + 0.5 - K[0, 2]) / K[0, 0] * d, (v + 0.5 - K[1, 2]) / K[1, 1] * d, d], axis=1)
        inside = np.einsum("ij,ij->i", cam, cam) <= self.config.max_range_m**2
        pts = cam[inside] @ T_world_cam[:3, :3].T + T_world_cam[:3, 3]
        ids = ids[take][inside]
        if ids.size == 0:
            return
        order = np.argsort(ids, kind="stable")
        ids, pts = ids[order], pts[order]
        starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])  # one run of points per instance
        self._glimpsed.update(zip(ids[starts].tolist(), self._run_boxes(pts, starts), strict=True))

    def _voxel_box(self, voxel_centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The box (min, max corners) around voxels (n x 3 centres)."""
        return self._run_boxes(voxel_centres, np.zeros(1, dtype=int))[0]

    def _voxel_boxes(self, voxels: Mapping[int, np.ndarray]) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """``_voxel_box`` of every instance (id -> n x 3 centres) at once: one reduction over all the voxels, not
        two numpy calls per object (a store's build boxes hundreds)."""
        if not voxels:
            return {}
        starts = np.cumsum([0, *(len(v) for v in voxels.values())])[:-1]
        return dict(zip(voxels, self._run_boxes(np.concatenate(list(voxels.values())), starts), strict=True))

    def _run_boxes(self, pts: np.ndarray, starts: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """The box (min, max corners) around each run of points (n x 3) beginning at ``starts``, half a voxel out
        (a point is a voxel's centre, or a pixel's hit boxed like one)."""
        half = self.config.resolution_m / 2
        lows, highs = np.minimum.reduceat(pts, starts) - half, np.maximum.reduceat(pts, starts) + half
        return list(zip(lows, highs, strict=True))

    def _closest_viewpoints(self, objects: Sequence[int], xy: np.ndarray) -> np.ndarray:
        """Per object, the robot position it was seen from nearest to its ``xy`` row (the first of equals; that
        row itself when none is known), for all objects at once: a store's build has hundreds."""
        seen = [list(self._viewpoints.get(i, {}).values()) for i in objects]
        counts = np.array([len(v) for v in seen], dtype=int)
        closest = np.array(xy, dtype=float).reshape(-1, 2)
        if not counts.any():
            return closest
        points = np.array([p for v in seen for p in v], dtype=float)
        owner = np.repeat(np.arange(len(seen)), counts)
        nearest_first = np.lexsort((np.linalg.norm(points - closest[owner], axis=1), owner))  # stable: ties by order
        known = counts > 0
        closest[known] = points[nearest_first[(np.cumsum(counts) - counts)[known]]]
        return closest

    def _nearest_visible(self, graph: NavGraph, nodes: np.ndarray, p: np.ndarray, blocked, grid: Grid) -> int:
        """Index (into graph) of the closest of ``nodes`` seeing p, else the closest; -1 if none."""
        if nodes.size == 0:
            return -1
        order = nodes[np.argsort(np.linalg.norm(graph.xy[nodes] - p, axis=1))[: self.config.assignment_k]]
        seen = line_of_sight(p, graph.xy[order], blocked, grid)
        return int(order[np.argmax(seen)] if seen.any() else order[0])

    def _robot_component(self, graph: NavGraph, robot: np.ndarray, blocked, grid: Grid, path: np.ndarray) -> np.ndarray:
        """Node mask of the (door-uncut) graph component the robot stands in, joined with the components
        whose nodes ``path`` points see within ``PATH_JOIN_M``."""
        node = self._nearest_visible(graph, np.arange(graph.n_nodes), robot, blocked, grid)
        if node < 0:
            return np.zeros(graph.n_nodes, dtype=bool)
        comp = graph.components()
        keep = {int(comp[node])}
        if len(path):
            dist, near = cKDTree(graph.xy).query(path, distance_upper_bound=PATH_JOIN_M)
            hit = np.isfinite(dist)
            path, near = path[hit], near[hit]
            elsewhere = comp[near] != comp[node]
            for p, i in zip(path[elsewhere], near[elsewhere]):
                if int(comp[i]) not in keep and line_of_sight(p, graph.xy[i : i + 1], blocked, grid)[0]:
                    keep.add(int(comp[i]))
        return np.isin(comp, sorted(keep))

    @staticmethod
    def _retraceable(path_xy: Sequence[Sequence[float]], occ: np.ndarray, grid: Grid) -> np.ndarray:
        """The points (n x 2) of the robot's path after the last one on a cell now occupied (a door
        closed, an item put down): the robot can drive back along them."""
        path = np.asarray(path_xy, dtype=float).reshape(-1, 2)
        cells = grid.cell_of(path)
        on_map = (cells >= 0).all(axis=1) & (cells < occ.shape).all(axis=1)
        occupied = np.zeros(len(path), dtype=bool)
        occupied[on_map] = occ[cells[on_map, 0], cells[on_map, 1]] == OCCUPIED
        start = int(np.flatnonzero(occupied)[-1]) + 1 if occupied.any() else 0
        return path[start:]

    def _attach(self, graph: NavGraph, labels: np.ndarray, points: np.ndarray, blocked, grid: Grid) -> np.ndarray:
        """Node index (labelled nodes only, -1 if none) each point belongs to."""
        labelled = np.flatnonzero(labels >= 0)
        return np.array([self._nearest_visible(graph, labelled, p, blocked, grid) for p in points], dtype=np.int64)

    @staticmethod
    def _through_openings(
        graph: NavGraph, labels: np.ndarray, keep: np.ndarray, points: np.ndarray, node: np.ndarray, occ, grid: Grid
    ) -> np.ndarray:
        """Frontier attachments moved into the robot's component where the free space they border runs
        into it: the part of a room seen through a narrow opening (a door ajar, a doorway glimpsed from
        the side) is a strip too thin for the graph, so its frontier would hang on a region out of reach,
        and the room it leads to would offer none. It goes to the nearest node of the robot's component in
        the same patch of seen-free space: explore() drives through the opening to it."""
        out = {i for i, n in enumerate(node.tolist()) if n < 0 or not keep[n]}
        reachable = np.flatnonzero(keep & (labels >= 0))
        if not out or reachable.size == 0:
            return node
        patches, _ = ndimage.label(occ == FREE, structure=np.ones((3, 3), dtype=bool))
        node_patch = _patch_at(patches, grid, graph.xy[reachable])
        point_patch = _patch_at(patches, grid, points)
        node = node.copy()
        for i in sorted(out):
            mine = reachable[(node_patch == point_patch[i]) & (point_patch[i] > 0)]
            if mine.size:
                node[i] = mine[np.argmin(np.linalg.norm(graph.xy[mine] - points[i], axis=1))]
        return node

    def _within_reach(
        self,
        graph: NavGraph,
        labels: np.ndarray,
        keep: np.ndarray,
        xy: np.ndarray,
        assigned: np.ndarray,
        doors: np.ndarray,
        blocked: np.ndarray,
        grid: Grid,
    ) -> np.ndarray:
        """Region labels with every object whose region (Eq. 1) is out of reach given the region within reach
        of the nearest node that sees it. Eq. 1 gives an object its closest node's region when the nodes near
        it and near its viewpoint share none, and that node may lie in a pocket the graph cannot enter (beside
        a car the robot just opened: packing_car_for_trip seed 1 lost the car from its graph there and
        searched the lawn for it). What is seen only through a wall or a window stays out of reach. A door
        goes to the nearest region within reach, seen or not: it joins two rooms, and once opened its leaf no
        longer separates them, so Eq. 1 may give it to the room behind, which the robot has not reached."""
        kept_labels = np.unique(labels[keep & (labels >= 0)])
        reachable = np.flatnonzero(keep & (labels >= 0))
        lost = np.flatnonzero(~np.isin(assigned, kept_labels))
        if lost.size == 0 or reachable.size == 0:
            return assigned
        assigned = assigned.copy()
        for i in lost.tolist():
            order = reachable[
                np.argsort(np.linalg.norm(graph.xy[reachable] - xy[i], axis=1))[: self.config.assignment_k]
            ]
            seen = line_of_sight(xy[i], graph.xy[order], blocked, grid)
            if seen.any() or doors[i]:
                assigned[i] = labels[order[int(np.argmax(seen))]]
        return assigned

    def _stable_ids(self, graph: NavGraph, labels: np.ndarray) -> list[str]:
        """Region id per label, inheriting ids through remembered anchors (see module docstring)."""
        k = int(labels.max()) + 1 if labels.size else 0
        if k == 0:
            return []
        labelled = np.flatnonzero(labels >= 0)
        tree = cKDTree(graph.xy[labelled])
        claims: dict[int, list[str]] = {}
        for rid, anchor in self._anchors.items():
            dist, i = tree.query(anchor)
            if dist <= 2 * self.config.sparsify_threshold_m:
                claims.setdefault(int(labels[labelled[i]]), []).append(rid)
        ids: list[str] = []
        for lab in range(k):
            owned = sorted(claims.get(lab, []), key=lambda r: int(r.split("_")[1]))
            if owned:
                rid = owned[0]
                for retired in owned[1:]:
                    del self._anchors[retired]
            else:
                rid = f"region_{self._next_region}"
                self._next_region += 1
                members = np.flatnonzero(labels == lab)
                centre = graph.xy[members].mean(0)
                self._anchors[rid] = graph.xy[members[np.argmin(np.linalg.norm(graph.xy[members] - centre, axis=1))]]
            ids.append(rid)
        return ids

    def _assemble(
        self,
        rg: RegionGraph,
        region_ids: list[str],
        keep: np.ndarray,
        objects: list[int],
        boxes: Mapping[int, tuple[np.ndarray, np.ndarray]],
        frontier_node: np.ndarray,
        robot: np.ndarray,
        occ: np.ndarray,
        grid: Grid,
    ) -> SceneGraph:
        """Put the pipeline's graph, reduced to the ``keep`` node mask, into the data model."""
        graph, labels = rg.graph, rg.labels
        sub_index = np.cumsum(keep) - 1
        emask = keep[graph.edges[:, 0]] & keep[graph.edges[:, 1]]
        node_region = [region_ids[lab] if lab >= 0 else None for lab in labels[keep]]
        kept = set(np.unique(labels[keep & (labels >= 0)]).tolist())

        obj_nodes: dict[str, ObjectNode] = {}
        for iid, lab in zip(objects, rg.assigned.tolist()):
            if lab in kept:
                node = self._object_node(iid, region_ids[lab], boxes[iid])
                obj_nodes[node.id] = node
        held = [iid for iid, info in self._instances.items() if info.held and iid in boxes]
        for iid in held:
            node = self._object_node(iid, None, boxes[iid])
            obj_nodes[node.id] = node

        regions: dict[str, RegionNode] = {}
        for lab in sorted(kept):
            rid = region_ids[lab]
            members = np.flatnonzero(keep & (labels == lab))
            fr = [tuple(map(float, p)) for p, n in zip(rg.frontier_xy, frontier_node) if n >= 0 and labels[n] == lab]
            regions[rid] = RegionNode(
                id=rid,
                room_label=self._room_labels.get(rid),
                centroid=tuple(map(float, graph.xy[members].mean(0))),
                nav_nodes=sub_index[members].tolist(),
                frontiers=fr,
            )

        relations = self._relations(
            [o for o in obj_nodes.values() if o.category != "door" and not o.held],
            held={o.id for o in obj_nodes.values() if o.held},
        )

        robot_node = -1
        labelled_kept = np.flatnonzero(keep & (labels >= 0))
        if labelled_kept.size:
            robot_node = labelled_kept[np.argmin(np.linalg.norm(graph.xy[labelled_kept] - robot, axis=1))]
        self._step += 1
        return SceneGraph(
            step=self._step - 1,
            robot=RobotNode(
                position=(float(robot[0]), float(robot[1])),
                region_id=region_ids[labels[robot_node]] if robot_node >= 0 else None,
            ),
            regions=regions,
            objects=obj_nodes,
            relations=relations,
            nav=NavGraphData(
                node_xy=graph.xy[keep],
                edges=sub_index[graph.edges[emask]],
                weights=graph.weights[emask],
                door_edges=rg.cut[emask],
                node_region=node_region,
            ),
            occupancy=OccupancyMap(grid=occ, origin_xy=grid.origin_xy, resolution_m=grid.resolution_m),
        )

    def _relations(self, placed: list[ObjectNode], held: set[str]) -> list[Relation]:
        """Spatial relations among the placed objects: as perceived where perception reports how an
        object rests (what the world did; on or in the ``held`` object for what the robot carries
        with it), from box geometry for the others."""
        ids = {o.id for o in placed} | held
        relations = []
        for o in placed:
            rests = self._instances[o.instance_id].rests
            if rests is not None and rests[1] in ids:
                relations.append(Relation(subject=o.id, predicate=rests[0], object=rests[1]))
        boxes_min = np.array([o.bbox.min for o in placed]).reshape(-1, 3)
        boxes_max = np.array([o.bbox.max for o in placed]).reshape(-1, 3)
        relations += [
            Relation(subject=placed[a].id, predicate=p, object=placed[b].id)
            for a, p, b in spatial_relations(
                boxes_min, boxes_max, tol_m=self.config.relation_tol_m, inside_fraction=self.config.inside_fraction
            )
            if self._instances[placed[a].instance_id].rests is None
        ]
        return relations

    def _object_node(self, iid: int, region_id: str | None, box: tuple[np.ndarray, np.ndarray]) -> ObjectNode:
        """The node of instance ``iid``; the last build's (a frozen model) when it was made from the same
        perception, region and box, as for most objects at every step: making one costs 17 us, and a store's
        graph holds hundreds."""
        info = self._instances[iid]
        lo, hi = box
        key = (info, region_id, lo.tobytes(), hi.tobytes())
        last = self._nodes.get(iid)
        if last is not None and last[0] == key:
            return last[1]
        node = ObjectNode(
            id=info.label,
            category=info.category,
            instance_id=iid,
            label=info.label,
            region_id=region_id,
            position=tuple(map(float, (lo + hi) / 2)),
            bbox=Box3D(min=tuple(map(float, lo)), max=tuple(map(float, hi))),
            open=info.open,
            held=info.held,
        )
        self._nodes[iid] = (key, node)
        return node


def _carry_facts(info: InstanceInfo) -> tuple[str, tuple[str, str | None] | None, bool]:
    """What ``SceneGraphBuilder._pick_up_contents`` reads of an instance: its label, what it rests on, whether held."""
    return info.label, info.rests, info.held


def _patch_at(patches: np.ndarray, grid: Grid, points: np.ndarray) -> np.ndarray:
    """The label in ``patches`` (0: none) of the cell under each point (n x 2); 0 off the grid."""
    cells = grid.cell_of(np.asarray(points, dtype=float).reshape(-1, 2))
    on = ((cells >= 0) & (cells < patches.shape)).all(axis=1)
    out = np.zeros(len(cells), dtype=patches.dtype)
    out[on] = patches[cells[on, 0], cells[on, 1]]
    return out
