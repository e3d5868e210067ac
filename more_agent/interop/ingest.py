"""A second source of observations for the mapping: posed, labelled frames from outside the simulator
(a ROS 2 bag, a robot), fused frame by frame into the same :class:`~more_agent.scene_graph.SceneGraphBuilder`
the simulator's robot uses.

:class:`FrameMapper` consumes :class:`~more_agent.interop.bag_reader.SensorFrame` objects (depth,
semantic, instance, label table, intrinsics, pose); ``ingest_bag`` runs a whole bag through one.
Instances the label table does not name get their category from the semantic image (the class most of
their pixels show) and an alphabetical label in order of first observation ('chair A', 'chair B'),
as the simulator labels what the robot sees.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from more_agent.interop.bag_contract import BagError, BagTopics, InstanceLabel
from more_agent.interop.bag_reader import BagStream, SensorFrame
from more_agent.mapping import MappingConfig
from more_agent.scene_graph import InstanceInfo, SceneGraph, SceneGraphBuilder

UNLABELED = "unlabeled"
"""Category of an instance whose pixels show no named class."""


def letters(i: int) -> str:
    """0 -> A, 25 -> Z, 26 -> AA: the instance letters of MORE's labels."""
    return (letters(i // 26 - 1) if i >= 26 else "") + chr(ord("A") + i % 26)


class FrameMapper:
    """Fuses external frames into a scene-graph builder and keeps the robot's path."""

    def __init__(self, class_names: Sequence[str], config: MappingConfig | None = None) -> None:
        self.class_names = list(class_names)
        self.builder = SceneGraphBuilder(self.class_names, config)
        self.path: list[tuple[float, float]] = []
        self.frames = 0
        self._labels: dict[int, str] = {}
        self._per_category: dict[str, int] = {}

    def add(self, frame: SensorFrame) -> None:
        """Fuse one frame (the items it reports as put down, or inside what was just opened, are kept at
        their boxes first)."""
        for iid, (lo, hi) in [*frame.placed.items(), *frame.revealed.items()]:
            self.builder.remember(iid, lo, hi)
        infos = {iid: self._info(iid, entry) for iid, entry in frame.instances.items()}
        for iid in np.unique(frame.instance[frame.instance > 0]).tolist():
            if iid not in infos and iid not in self._labels:
                infos[iid] = self._info(iid, InstanceLabel(category=self._category(frame, iid)))
        self.builder.integrate(
            frame.depth, frame.semantic, frame.instance, frame.K, frame.T_world_cam, infos, frame.robot_xy
        )
        if not self.path or self.path[-1] != frame.robot_xy:
            self.path.append(frame.robot_xy)
        self.frames += 1

    def build(self) -> SceneGraph:
        """The scene graph of every frame so far, from the last robot position."""
        if not self.path:
            raise BagError("no frame was fused: nothing to build a scene graph from")
        return self.builder.build(self.path[-1], self.path)

    def _info(self, iid: int, entry: InstanceLabel) -> InstanceInfo:
        label = entry.label or self._labels.get(iid)
        if label is None:
            k = self._per_category.get(entry.category, 0)
            self._per_category[entry.category] = k + 1
            label = f"{entry.category} {letters(k)}"
        self._labels[iid] = label
        return InstanceInfo(label=label, category=entry.category, open=entry.open, held=entry.held, rests=entry.rests)

    def _category(self, frame: SensorFrame, iid: int) -> str:
        classes = np.bincount(frame.semantic[frame.instance == iid].clip(0))
        cls = int(np.argmax(classes))
        return self.class_names[cls] if 0 < cls < len(self.class_names) else UNLABELED


@dataclass(frozen=True)
class IngestResult:
    """A bag's scene graph and how it went."""

    graph: SceneGraph
    class_names: list[str]
    frames: int
    skipped: int
    """Image stamps dropped as incomplete."""
    fuse_s: float
    """Seconds spent reading and fusing the frames."""
    build_s: float
    """Seconds spent building the scene graph."""
    path: list[tuple[float, float]]


def ingest_bag(path: Path, topics: BagTopics | None = None, config: MappingConfig | None = None) -> IngestResult:
    """Read a bag frame by frame through :class:`FrameMapper` and build its scene graph."""
    stream = BagStream(path, topics)
    try:
        mapper = FrameMapper(stream.class_names, config)
        t = time.perf_counter()
        for frame in stream.frames():
            mapper.add(frame)
        fused = time.perf_counter()
        graph = mapper.build()
        built = time.perf_counter()
    finally:
        stream.close()
    return IngestResult(
        graph=graph,
        class_names=mapper.class_names,
        frames=mapper.frames,
        skipped=stream.skipped,
        fuse_s=fused - t,
        build_s=built - fused,
        path=mapper.path,
    )
