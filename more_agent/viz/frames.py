"""Camera frames as pictures: RGB, depth colourised, semantic colourised.

``more-agent run ... --save-frames`` writes them (:mod:`more_agent.eval.episode_folder`). Inputs are
plain arrays so that frames from the renderer (NaN = invalid depth) and from the environment's
observations (0 = invalid depth) both work.
"""

from __future__ import annotations

import numpy as np
from matplotlib import colormaps

from more_agent.sim.camera import MAX_RANGE_M
from more_agent.sim.render import class_colors


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


def frame_pictures(
    rgb: np.ndarray, depth: np.ndarray, semantic: np.ndarray, class_names: list[str], max_range_m: float = MAX_RANGE_M
) -> dict[str, np.ndarray]:
    """The three pictures of a camera frame, (H, W, 3) uint8 each: ``rgb``, ``depth`` and ``semantic`` colourised."""
    return {
        "rgb": np.asarray(rgb, dtype=np.uint8),
        "depth": colorize_depth(depth, max_range_m),
        "semantic": colorize_semantic(semantic, class_names),
    }
