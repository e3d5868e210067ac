"""Set-of-mark annotation of a camera frame: mask outlines and numbered marks on the objects a VLM may pick.

Drawn as BUMBLE's public code draws its prompt images (a filled white disc with the object's id in
black, about 3 % of the image size, kept inside the image), with two changes for our ground-truth
segmentation: the disc sits at the point of the object's mask farthest from the mask's border
(BUMBLE uses the box centre, which can fall off a concave object), and each marked mask gets a
coloured outline so that the mark's object is unambiguous in clutter. Marks are numbered 1..n in
the order given; ids are instance ids of the renderer's instance image (0 = background: floor,
carpet, lawn, driveway, walls, windows; the renderer has no ceiling).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from skimage.segmentation import find_boundaries

MARK_RADIUS_FRACTION = 0.035
"""Disc radius as a fraction of the image's short side (9 px on a 256x256 frame)."""


def _rgb(hex_code: str) -> tuple[int, int, int]:
    """'e6194b' -> (230, 25, 75)."""
    r, g, b = bytes.fromhex(hex_code)
    return r, g, b


OUTLINE_COLORS: tuple[tuple[int, int, int], ...] = tuple(
    map(_rgb, "e6194b 3cb44b ffe119 0082c8 f58230 911eb4 46f0f0 f032e6 d2f53c fabed4 008080 aa6e28".split())
)
"""Outline colour of mark k is ``OUTLINE_COLORS[(k - 1) % 12]`` (a qualitative palette)."""


@dataclass(frozen=True)
class Mark:
    """One numbered mark: its number, the instance id it marks and its anchor (u = column, v = row), a
    pixel of the object's mask; the disc is drawn there, shifted inward when that is near the image border."""

    number: int
    instance_id: int
    anchor: tuple[int, int]


@dataclass(frozen=True, eq=False)
class MarkedImage:
    """An annotated frame and its marks, in number order."""

    rgb: np.ndarray
    marks: tuple[Mark, ...]


def mark_anchor(mask: np.ndarray) -> tuple[int, int]:
    """(u, v) of the mask pixel farthest from the mask's border (ties: first in row-major order)."""
    rows, cols = np.nonzero(mask)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    crop = np.pad(mask[r0:r1, c0:c1], 1)
    dist = ndimage.distance_transform_edt(crop)
    r, c = np.unravel_index(int(np.argmax(dist)), dist.shape)
    return int(c0 + c - 1), int(r0 + r - 1)


@functools.cache
def _font(size: int):  # noqa: ANN202 - PIL font type
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def annotate_marks(rgb: np.ndarray, instance: np.ndarray, instance_ids: Sequence[int]) -> MarkedImage:
    """``rgb`` with an outline and a numbered disc on each of ``instance_ids`` (numbered 1.. in that order).

    Ids absent from ``instance`` (or 0) get no mark; numbering skips nothing, so mark k is the k-th
    id that is visible.
    """
    from PIL import Image, ImageDraw

    visible = [int(i) for i in instance_ids if i != 0 and np.any(instance == i)]
    out = np.array(rgb, dtype=np.uint8, copy=True)
    if not visible:
        return MarkedImage(out, ())
    lookup = np.zeros(int(instance.max()) + 1, dtype=np.int32)
    lookup[visible] = np.arange(1, len(visible) + 1)
    numbered = lookup[np.clip(instance, 0, None)]
    edges = find_boundaries(numbered, mode="inner") & (numbered > 0)
    colors = np.array(OUTLINE_COLORS, dtype=np.uint8)
    out[edges] = colors[(numbered[edges] - 1) % len(colors)]

    h, w = instance.shape
    radius = max(4, round(MARK_RADIUS_FRACTION * min(h, w)))
    font = _font(max(8, round(1.3 * radius)))
    image = Image.fromarray(out, mode="RGB")
    draw = ImageDraw.Draw(image)
    marks = []
    for number, iid in enumerate(visible, start=1):
        u, v = mark_anchor(numbered == number)
        cu, cv = min(max(u, radius), w - 1 - radius), min(max(v, radius), h - 1 - radius)
        draw.ellipse((cu - radius, cv - radius, cu + radius, cv + radius), fill=(255, 255, 255), outline=(0, 0, 0))
        draw.text((cu, cv), str(number), fill=(0, 0, 0), font=font, anchor="mm")
        marks.append(Mark(number=number, instance_id=iid, anchor=(u, v)))
    return MarkedImage(np.asarray(image), tuple(marks))
