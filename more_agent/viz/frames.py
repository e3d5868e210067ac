"""Camera frames as pictures: RGB, depth colourised, semantic colourised, written as PNG.

Used by ``more-agent run ... --save-frames`` (``FrameWriter``, under ``DIR/frames/``). Inputs are plain arrays so that frames from the
renderer (NaN = invalid depth) and from the environment's observations (0 = invalid depth) both work.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import colormaps
from PIL import Image

from more_agent.sim.camera import MAX_RANGE_M
from more_agent.sim.render import Frame, class_colors


def colorize_depth(depth: np.ndarray, max_range_m: float = MAX_RANGE_M, cmap: str = "turbo") -> np.ndarray:
    """(H, W, 3) uint8 picture of a depth image: near to far along ``cmap``, invalid (NaN or <= 0) black."""
    valid = np.isfinite(depth) & (depth > 0)
    scaled = np.clip(np.where(valid, depth, 0.0) / max_range_m, 0.0, 1.0)
    rgb = (colormaps[cmap](scaled)[..., :3] * 255).round().astype(np.uint8)
    rgb[~valid] = 0
    return rgb


def colorize_semantic(semantic: np.ndarray, class_names: list[str]) -> np.ndarray:
    """(H, W, 3) uint8 picture of a semantic image with the renderer's per-class palette."""
    return class_colors(class_names)[semantic]


def save_frame(directory: str | Path, stem: str, *, rgb: np.ndarray, depth: np.ndarray, semantic: np.ndarray,
               class_names: list[str], max_range_m: float = MAX_RANGE_M) -> list[Path]:
    """Write ``<stem>_rgb.png``, ``<stem>_depth.png`` and ``<stem>_semantic.png`` into ``directory``; return their paths."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    pictures = {
        "rgb": np.asarray(rgb, dtype=np.uint8),
        "depth": colorize_depth(depth, max_range_m),
        "semantic": colorize_semantic(semantic, class_names),
    }
    paths = []
    for kind, image in pictures.items():
        path = out / f"{stem}_{kind}.png"
        Image.fromarray(image).save(path)
        paths.append(path)
    return paths


FRAMES_DIR = "frames"
"""Folder of an episode's sensor frames (``more-agent run ... --save-frames``)."""


class FrameWriter:
    """Writes every frame it is given as numbered PNG triples (``frame_0000_rgb.png`` ...) into a folder.

    ``class_names`` is read when a frame is written, so a world that registers new categories later
    still gets the right semantic colours.
    """

    def __init__(self, directory: str | Path, class_names: list[str]) -> None:
        self.directory = Path(directory)
        self.class_names = class_names
        self.count = 0

    def __call__(self, frame: Frame) -> None:
        save_frame(self.directory, f"frame_{self.count:04d}", rgb=frame.rgb, depth=frame.depth,
                   semantic=frame.semantic, class_names=self.class_names)
        self.count += 1


def frames_written(directory: str | Path) -> int:
    """How many frames a :class:`FrameWriter` has written into ``directory`` (0 when it does not exist)."""
    directory = Path(directory)
    return sum(1 for _ in directory.glob("frame_*_rgb.png")) if directory.is_dir() else 0
