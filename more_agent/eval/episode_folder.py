"""The episode folder: the names of its files and the one place that writes them.

The episode runner hands this module what an episode produced: the record, each step's goal status
and the planner's :class:`~more_agent.planners.base.StepTrace`, every rendered frame, the world for
the map. The viewer, the report and ``eval --resume`` find the files through the same names. Which
file holds what, and when it is written: docs/evaluation.md, "Episode folder". Pictures are drawn by
:mod:`more_agent.viz` (arrays and PNG bytes); only this module touches the disk.
"""

from __future__ import annotations

import io
import json
import logging
import shutil
from collections.abc import Callable, Collection, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from more_agent.errors import UserError
from more_agent.eval.pictures import pictures_enabled
from more_agent.record_validation import parse_record, record_json
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.safe_files import append_text, make_dir, read_bounded, write_atomic

if TYPE_CHECKING:
    import numpy as np

    from more_agent.planners.base import StepTrace
    from more_agent.scene_graph import SceneGraph
    from more_agent.sim.goals import GoalStatus
    from more_agent.sim.labels import InstanceLabels
    from more_agent.sim.render import Frame
    from more_agent.sim.world import World

log = logging.getLogger(__name__)

EPISODE_FILE = "episode.json"
MAP_FILE = "map.png"
TIMELINE_FILE = "timeline.jsonl"
STEPS_FILE = "steps.jsonl"
VIEWER_FILE = "viewer.html"
FRAMES_DIR = "frames"
GRAPHS_DIR = "graphs"
VLM_IMAGES_DIR = "vlm"

_PNG_END = b"IEND\xaeB`\x82"


def map_is_complete(path: Path) -> bool:
    """Whether ``path`` is a whole PNG (a crash on a full disk leaves none or a truncated one)."""
    try:
        with open(path, "rb") as f:
            f.seek(-12, 2)
            return f.read().endswith(_PNG_END)
    except OSError:
        return False


def read_record(path: Path) -> EpisodeRecord:
    """The validated record of an ``episode.json`` (a UserError naming the file and the problem)."""
    return parse_record(read_bounded(path, what="episode record"), source=str(path))


def folder_record(path: Path) -> EpisodeRecord | None:
    """The record of the finished episode in the folder ``path``; None when it holds none, or none that reads."""
    record_path = Path(path) / EPISODE_FILE
    if not record_path.is_file() or record_path.is_symlink():
        return None
    try:
        return read_record(record_path)
    except UserError:
        return None


def check_folder_for(path: Path, spec: EpisodeSpec) -> None:
    """Raise a UserError when the folder ``path`` holds a finished episode of another spec than ``spec``.

    An earlier run of the same episode, or an unfinished or unreadable one, is not refused: the
    episode runner clears its files (:meth:`EpisodeFolder.clear`) before writing the new ones.
    """
    old = folder_record(path)
    if old is None:
        return
    same = (old.task, old.seed, old.planner, old.llm, old.start) == (
        spec.task,
        spec.seed,
        spec.planner,
        spec.llm,
        spec.start,
    )
    same = same and old.distractors in (None, spec.distractors)
    same = same and (spec.scene is None or spec.scene.endswith(".json") or spec.scene == old.scene)
    if not same:
        raise UserError(
            f"{path} holds another episode ({old.task} in {old.scene}, seed {old.seed}, planner {old.planner}, "
            f"llm {old.llm}, start {old.start}); choose another --out, or delete that folder to replace it"
        )


class EpisodeFolder:
    """One episode's folder: where each file lives (the ``*_path`` / ``*_dir`` attributes and methods,
    which reading code such as the viewer uses), and writing them.

    ``frames`` writes every rendered frame and the VLM's images, ``graphs`` each step's scene graph
    (with its picture when ``graph_pictures``: about 0.4 s a step, which the viewer does not need).
    """

    def __init__(self, path: Path, *, frames: bool = False, graphs: bool = False, graph_pictures: bool = False) -> None:
        self.path = Path(path)
        self.frames = frames
        self.graphs = graphs
        self.graph_pictures = graph_pictures
        self.frames_written = 0
        self.record_path = self.path / EPISODE_FILE
        self.map_path = self.path / MAP_FILE
        self.timeline_path = self.path / TIMELINE_FILE
        self.steps_path = self.path / STEPS_FILE
        self.viewer_path = self.path / VIEWER_FILE
        self.frames_dir = self.path / FRAMES_DIR
        self.graphs_dir = self.path / GRAPHS_DIR

    # -- where things are ---------------------------------------------------------------------
    def frame_path(self, index: int, kind: str) -> Path:
        """One picture (``rgb``, ``depth``, ``semantic``) of the ``index``-th rendered frame."""
        return self.frames_dir / f"frame_{index:04d}_{kind}.png"

    def graph_path(self, step: int, suffix: str = ".json") -> Path:
        """The scene graph of ``step`` (``.json``), its occupancy grid (``_occupancy.png``) or picture (``.png``)."""
        return self.graphs_dir / f"step_{step:03d}{suffix}"

    def vlm_image_path(self, step: int, kind: str) -> Path:
        """An annotated image (``view``, ``object``) the VLM was shown in ``step``."""
        return self.path / VLM_IMAGES_DIR / f"step_{step:03d}_{kind}.png"

    def owned_paths(self) -> list[Path]:
        """Every file and folder of an episode this module writes (what :meth:`clear` removes)."""
        return [
            self.record_path,
            self.map_path,
            self.timeline_path,
            self.steps_path,
            self.viewer_path,
            self.frames_dir,
            self.graphs_dir,
            self.path / VLM_IMAGES_DIR,
        ]

    # -- writing --------------------------------------------------------------------------------
    def clear(self) -> None:
        """Remove an earlier episode's files from the folder (only the names this module owns; a
        symlink is removed itself, never followed), so a new episode never shows an old one's steps."""
        for path in self.owned_paths():
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink(missing_ok=True)

    def start(self, *, steps_log: bool) -> None:
        """Begin the per-step files of a run into this folder: an empty ``timeline.jsonl`` and, for a
        planner that logs its steps (LLM and VLM planners), an empty ``steps.jsonl``."""
        self.path.mkdir(parents=True, exist_ok=True)
        write_atomic(self.timeline_path, b"", durable=False)
        if steps_log:
            write_atomic(self.steps_path, b"", durable=False)

    def frame_writer(self, class_names: list[str]) -> Callable[[Frame], None] | None:
        """The hook that writes every rendered frame as a numbered PNG triple (None without ``frames``).

        ``class_names`` is read when a frame is written, so a world that registers new categories
        later still gets the right semantic colours.
        """
        if not self.frames:
            return None

        def write(frame: Frame) -> None:
            from more_agent.viz.frames import frame_pictures  # lazy: matplotlib only when writing frames

            make_dir(self.frames_dir)
            for kind, picture in frame_pictures(frame.rgb, frame.depth, frame.semantic, class_names).items():
                _save_png(picture, self.frame_path(self.frames_written, kind))
            self.frames_written += 1

        return write

    def write_step(self, record: EpisodeRecord, status: GoalStatus, targets: list[str], trace: StepTrace) -> None:
        """Everything of the step just recorded in ``record`` (its last action): the planner's trace
        (its ``steps.jsonl`` line, VLM images, scene graph, as asked) and the timeline line.
        ``targets`` are the action's arguments as instance labels ('fridge A'), as the robot's map names objects."""
        step = record.actions[-1].step
        if trace.log is not None:
            _append_line(self.steps_path, {"step": step, **trace.log})
        if self.frames:
            for kind, png in trace.pictures.items():
                path = self.vlm_image_path(step, kind)
                make_dir(path.parent)
                write_atomic(path, png, durable=False)
        if self.graphs and trace.graph is not None:
            self._write_graph(step, trace.graph)
        _append_line(
            self.timeline_path,
            {
                "step": step,
                "path_len": len(record.trajectory),
                "low_level_steps": record.low_level_steps,
                "frames": self.frames_written,
                "goals": [[c.text, c.satisfied] for c in status.conditions],
                "progress": round(status.progress, 4),
                "targets": targets,
            },
        )

    def _write_graph(self, step: int, graph: SceneGraph) -> None:
        from more_agent.viz.graph_plot import occupancy_png, scene_graph_png

        make_dir(self.graphs_dir)
        write_atomic(self.graph_path(step), graph.model_dump_json(), durable=False)
        if graph.occupancy is not None:
            write_atomic(self.graph_path(step, "_occupancy.png"), occupancy_png(graph.occupancy), durable=False)
        if self.graph_pictures:
            write_atomic(self.graph_path(step, ".png"), scene_graph_png(graph, title=f"step {step}"), durable=False)

    def write_map(
        self, record: EpisodeRecord, world: World | None, labels: InstanceLabels | None, labelled: Collection[str]
    ) -> None:
        """The map picture (when the world was built and pictures are on, ``eval.pictures``); a picture that
        fails is logged, never costs the record."""
        self.path.mkdir(parents=True, exist_ok=True)
        if world is None or labels is None or not pictures_enabled():
            return
        from more_agent.viz.trajectory import trajectory_map_png

        try:
            png = trajectory_map_png(
                world,
                labels,
                record.trajectory,
                title=f"{record.task} ({record.scene}, {record.planner})",
                labelled=labelled,
            )
            write_atomic(self.map_path, png)
        except Exception as e:  # noqa: BLE001 - a failed picture must not lose the record or change its outcome
            log.warning("could not draw %s: %s: %s", self.map_path, type(e).__name__, e)

    def write_record(self, record: EpisodeRecord) -> None:
        """``episode.json``, written last (with the final timings), all at once: a full disk leaves none."""
        self.path.mkdir(parents=True, exist_ok=True)
        write_atomic(self.record_path, record_json(record, indent=2) + "\n")

    def write_viewer(self, html: str, out: Path | None = None) -> Path:
        """The viewer page, to ``out`` (default ``viewer.html`` in the folder); return its path."""
        path = Path(out) if out is not None else self.viewer_path
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, html)
        return path


def _append_line(path: Path, line: Mapping[str, Any]) -> None:
    append_text(path, json.dumps(line) + "\n")


def _save_png(picture: np.ndarray, path: Path) -> None:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(picture).save(buf, format="PNG")
    write_atomic(path, buf.getvalue(), durable=False)
