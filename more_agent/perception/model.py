"""One episode's noisy perception: the per-episode draws, the frame and pose errors, and the names it gives.

:class:`NoisyPerception` turns each ground-truth observation into the one a detector with the spec's
errors reports (:mod:`more_agent.perception.noise`), keeps the odometry drift, and names what it sees:
an instance seen as another category or as a second piece gets a fresh label of the category it is
seen as (``InstanceLabels.fresh_label``), and :meth:`NoisyPerception.real_label` maps such a label back to the
real object's, so a magic action on it acts on the real object. It reads the simulator's world for
what a detector's errors depend on (sizes, kinds, categories, names) and never changes its state;
it names objects through the task instance's labels (``instance.labels``). Its
random generator is seeded by (episode seed, task), so an episode replays the same errors.
:class:`~more_agent.perception.robot.NoisyRobot` puts it between the simulator's robot and a planner.
"""

from __future__ import annotations

import re
import zlib
from collections.abc import Iterable, Mapping
from dataclasses import replace

import numpy as np

from more_agent.perception.noise import (
    DepthNoise,
    InstanceTables,
    drift_step,
    drifted_pose,
    perturb_instances,
)
from more_agent.perception.taxonomy import sibling_category
from more_agent.perception_spec import PerceptionSpec, parse_perception
from more_agent.robot import Frame, InstanceInfo
from more_agent.sim.labels import InstanceLabels
from more_agent.sim.world import World


def perception_for(text: str, world: World, labels: InstanceLabels, seed: int, task: str) -> NoisyPerception | None:
    """The perception errors of an episode of ``task`` and ``seed`` in ``world`` for a mode's canonical text;
    None for ground truth (or a noisy mode with every kind off)."""
    spec = parse_perception(text)
    return NoisyPerception(spec, world, labels, episode_seed(seed, task)) if spec.noisy else None


def episode_seed(seed: int, task: str) -> int:
    """The seed of an episode's perception errors: its world seed and task, so reruns draw alike."""
    return (seed * 1_000_003 + zlib.crc32(task.encode())) % 2**32


def draw_tables(world: World, spec: PerceptionSpec, rng: np.random.Generator) -> InstanceTables:
    """Per-instance sizes and the episode's draws of which instances are confused, split and merged."""
    objects = [o for o in world.objects.values() if o.instance_id > 0]
    n = max((o.instance_id for o in objects), default=0) + 1
    size, eligible, seen_class = np.zeros(n), np.zeros(n, dtype=bool), np.zeros(n, dtype=np.int64)
    vocabulary = {kind: sorted({o.category for o in objects if o.kind == kind}) for kind in ("item", "furniture")}
    for o in objects:
        size[o.instance_id] = float(np.max(np.asarray(o.size)))
        eligible[o.instance_id] = o.kind in ("item", "furniture")
        seen_class[o.instance_id] = world.semantic_id(o.category)
    own, by_id = seen_class.copy(), {o.instance_id: o for o in objects}
    draws = rng.random((3, n))
    for i in np.flatnonzero(eligible & (draws[0] < spec.confusion)):
        obj = by_id[int(i)]
        other = sibling_category(obj.category, vocabulary[obj.kind], rng)  # items for items, furniture for furniture
        if other is not None:
            seen_class[i] = world.semantic_id(other)  # a category of the world: no new class
    return InstanceTables(
        size_m=size,
        eligible=eligible,
        seen_class=seen_class,
        confused=seen_class != own,
        fragment=eligible & (draws[1] < spec.fragment),
        merge=eligible & (draws[2] < spec.merge),
    )


class NoisyPerception:
    """The perception errors of one episode (see the module docstring)."""

    def __init__(self, spec: PerceptionSpec, world: World, labels: InstanceLabels, seed: int) -> None:
        self.spec, self.world, self.labels, self.seed = spec, world, labels, seed
        self.rng = np.random.default_rng(seed)
        self.tables = draw_tables(world, spec, self.rng)
        self.fragments = len(self.tables.size_m)
        """Fragment ids: ``fragments + i`` is the second piece of instance ``i``."""
        self.drift = np.eye(3)
        self.depth_noise = DepthNoise(self.rng)
        self._names = {o.instance_id: o.name for o in world.objects.values() if o.instance_id > 0}
        self._labels: dict[int, str] = {}
        """Perceived id -> the fresh label of a confused instance or a fragment."""
        self.aliases: dict[str, str] = {}
        """Fresh label -> world name of the real object."""
        self._seen_as: dict[str, str] = {}
        """World label of a confused instance -> its fresh label."""
        n = self.fragments
        self.in_view, self.perceived = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        """Instances that were in view / perceived as themselves at least once."""

    def observe(
        self,
        frame: Frame,
        instances: Mapping[int, InstanceInfo],
        known: Iterable[int] = (),
        told: Iterable[int] = (),
    ) -> tuple[Frame, dict[int, InstanceInfo]]:
        """A ground-truth frame and what perception says of its instances as this perception reports them:
        noisy depth, perturbed semantic and instance images, the camera pose its odometry believes in;
        missed and merged instances dropped (unless ``known``: held, just acted on or released, which the
        robot knows without a camera), the rest named as seen. ``told`` (among ``known``): what the robot
        learns of without a camera (what opening showed, ``Observation.revealed``) counts as in view and, unless
        confused, as perceived (:meth:`observed`)."""
        found = perturb_instances(
            frame.depth, frame.semantic, frame.instance, float(frame.K[0, 0]), self.tables, self.spec.miss, self.rng
        )
        shown = np.zeros_like(found.in_view)
        shown[np.fromiter(told, dtype=np.int64)] = True
        self.in_view |= found.in_view | shown
        self.perceived |= (found.kept | shown) & ~self.tables.confused
        hidden = set(np.flatnonzero(found.in_view & ~found.kept).tolist()) - set(known) - {0}
        infos = {i: info for i, info in instances.items() if i not in hidden}
        seen = replace(
            frame,
            depth=self.depth_noise.apply(frame.depth, self.spec.depth),
            semantic=found.semantic,
            instance=found.instance,
            T_world_cam=drifted_pose(self.drift, frame.T_world_cam),
        )
        return seen, self._named(infos, found.split)

    def _named(self, infos: dict[int, InstanceInfo], split: np.ndarray) -> dict[int, InstanceInfo]:
        """``infos`` as this perception names them: confused instances under their seen category and a fresh
        label, one more entry per fragment (like its whole), supports named as perceived."""
        out = dict(infos)
        given = np.fromiter(infos, dtype=np.int64)
        given = given[(given > 0) & (given < self.fragments)]
        for i in [*given[self.tables.confused[given]].tolist(), *(split + self.fragments).tolist()]:
            info = infos.get(i - self.fragments if i >= self.fragments else i)
            if info is not None:
                label, category = self._name(i, info.category)
                out[i] = info.model_copy(update={"label": label, "category": category})
        if self._seen_as:
            for i, info in out.items():
                if info.rests is not None and info.rests[1] in self._seen_as:
                    out[i] = info.model_copy(update={"rests": (info.rests[0], self._seen_as[info.rests[1]])})
        return out

    def _name(self, perceived_id: int, category: str) -> tuple[str, str]:
        """(label, category) of a confused instance or a fragment (``category``: its whole's as reported)."""
        i = perceived_id - self.fragments if perceived_id >= self.fragments else perceived_id
        confused = bool(self.tables.confused[i])
        seen_as = self.world.class_names[int(self.tables.seen_class[i])] if confused else category
        if perceived_id not in self._labels:
            label = self.labels.fresh_label(seen_as)
            self._labels[perceived_id] = label
            self.aliases[label] = self._names[i]
            if confused and perceived_id < self.fragments:
                self._seen_as[self.labels.reserve(self.world.objects[self._names[i]])] = label
        return self._labels[perceived_id], seen_as

    def moved(self, xy: tuple[float, float], distance_m: float) -> None:
        """Odometry after driving ``distance_m`` from ``xy``."""
        self.drift = drift_step(self.drift, xy, distance_m, self.spec.drift, self.rng)

    def real_label(self, label: str) -> str:
        """The real object's label behind a label this perception made up; any other label as it is."""
        name = self.aliases.get(label.strip())
        return label if name is None else self.labels.reserve(self.world.objects[name])

    def perceived_text(self, text: str, acted_on: Mapping[str, str]) -> str:
        """``text`` (an action's feedback) naming objects as this perception does: each real label of
        ``acted_on`` as the label the robot acted on, every other confused instance under its fresh label
        (the item held when placing, a support), so no message shows a planner a name it never saw."""
        names = {**self._seen_as, **acted_on}
        if not names:
            return text
        pattern = re.compile("|".join(rf"\b{re.escape(k)}\b" for k in sorted(names, key=len, reverse=True)))
        return pattern.sub(lambda m: names[m.group(0)], text)

    def room_input(self, objects: Iterable[tuple[str, str]]) -> list[str]:
        """The categories the room classifier reads for (label, category) pairs: each object's, or, for the
        ``room`` share of objects (fixed per object and episode), a random other category of the world."""
        pool = sorted({o.category for o in self.world.objects.values() if o.kind in ("item", "furniture")})
        out = []
        for label, category in objects:
            draw = np.random.default_rng((self.seed, zlib.crc32(label.encode()))).random(2)
            out.append(pool[int(draw[1] * len(pool))] if draw[0] < self.spec.room and pool else category)
        return out

    def observed(self) -> set[str]:
        """World names of the objects perceived as themselves at least once (for rTP)."""
        return {self._names[i] for i in np.flatnonzero(self.perceived).tolist() if i in self._names}

    def misperceived(self, names: Iterable[str]) -> dict[str, str]:
        """Of the world objects ``names``, those in view at some point but never perceived as themselves,
        with how: seen as another category's label, merged into a neighbour, or not detected."""
        by_name = {v: k for k, v in self._names.items()}
        seen_as = {self._names[i]: lbl for i, lbl in self._labels.items() if i < self.fragments}
        out = {}
        for name in names:
            i = by_name.get(name)
            if i is None or not self.in_view[i] or self.perceived[i]:
                continue
            how = "merged into a neighbour" if self.tables.merge[i] else "not detected"
            out[name] = f"seen as {seen_as[name]}" if name in seen_as else how
        return out
