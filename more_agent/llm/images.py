"""Images in chat messages: PNG encoding, ``image_url`` content parts, OpenAI's image token rule.

A vision request is an ordinary chat message whose ``content`` is a list of parts
(``{"type": "text", ...}`` and ``{"type": "image_url", "image_url": {"url": "data:image/png;base64,...",
"detail": "low"}}``), as the OpenAI chat API takes it; the HTTP backend sends it unchanged.

Frames are 256x256 and sent at ``detail: low``: OpenAI bills a low-detail image a flat 85 tokens
and shows the model a 512x512 version of it, which holds a 256x256 frame without loss (``high``
would bill 85 + 170 per 512 px tile, 255 tokens for the same pixels). :func:`image_tokens` also
implements the high-detail rule for other sizes.

The response cache keys a request by the sha256 of each image's bytes instead of its base64 text
(:func:`cache_view`), so keys and the stored requests stay small and replay works for VLM calls.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import io
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

ImageDetail = Literal["low", "high"]

DEFAULT_DETAIL: ImageDetail = "low"
"""Detail level the planners send frames at (see module docstring)."""

LOW_DETAIL_TOKENS = 85
"""OpenAI's flat token cost of a low-detail image (and the base cost of a high-detail one)."""

TILE_TOKENS = 170
"""OpenAI's token cost of each 512x512 tile of a high-detail image."""

_DATA_URL_PREFIX = "data:image/png;base64,"


def png_bytes(rgb: np.ndarray) -> bytes:
    """An (H, W, 3) uint8 image as PNG bytes (fast compression: frames are flat-shaded)."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), mode="RGB").save(buffer, format="PNG", compress_level=1)
    return buffer.getvalue()


def image_part(png: bytes, *, detail: ImageDetail = DEFAULT_DETAIL) -> dict[str, Any]:
    """An ``image_url`` content part carrying ``png`` as a base64 data URL."""
    url = _DATA_URL_PREFIX + base64.b64encode(png).decode("ascii")
    return {"type": "image_url", "image_url": {"url": url, "detail": detail}}


def text_part(text: str) -> dict[str, Any]:
    """A ``text`` content part."""
    return {"type": "text", "text": text}


def png_size(png: bytes) -> tuple[int, int]:
    """(width, height) read from a PNG's IHDR chunk; ValueError when ``png`` is not a PNG."""
    if len(png) < 24 or png[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG image")
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")


def image_tokens(width: int, height: int, detail: ImageDetail = DEFAULT_DETAIL) -> int:
    """Prompt tokens OpenAI bills for one image (GPT-4o family rule).

    low: 85. high: scale to fit 2048x2048, then so that the short side is at most 768 px, then
    85 + 170 per 512 px tile.
    """
    if detail == "low":
        return LOW_DETAIL_TOKENS
    scale = min(1.0, 2048 / max(width, height))
    w, h = width * scale, height * scale
    scale = min(1.0, 768 / min(w, h))
    w, h = w * scale, h * scale
    return LOW_DETAIL_TOKENS + TILE_TOKENS * math.ceil(w / 512) * math.ceil(h / 512)


def _parts(content: Any) -> list[dict[str, Any]]:
    return [p for p in content if isinstance(p, dict)] if isinstance(content, list) else []


def _png_of(part: dict[str, Any]) -> bytes | None:
    """The image bytes of an ``image_url`` part with a base64 data URL, else None."""
    if part.get("type") != "image_url":
        return None
    url = str(part.get("image_url", {}).get("url", ""))
    head, sep, data = url.partition(";base64,")
    if not sep or not head.startswith("data:"):
        return None
    try:
        return base64.b64decode(data, validate=True)
    except binascii.Error:
        return None


def message_images(messages: Iterable[Any]) -> list[tuple[bytes, ImageDetail]]:
    """Every inline image of ``messages`` (chat message dicts) with its detail level, in order."""
    out: list[tuple[bytes, ImageDetail]] = []
    for m in messages:
        for part in _parts(m.get("content")):
            png = _png_of(part)
            if png is not None:
                detail = part["image_url"].get("detail", "high")
                out.append((png, "low" if detail == "low" else "high"))
    return out


@dataclass(frozen=True)
class ImageStats:
    """Images of one request: how many, their bytes (decoded) and the prompt tokens OpenAI bills for them."""

    images: int = 0
    image_bytes: int = 0
    image_tokens: int = 0


def image_stats(messages: Sequence[Any]) -> ImageStats:
    """Count the inline images of a request (size read from each PNG header; 256x256 if unreadable)."""
    images = message_images(messages)
    tokens = 0
    for png, detail in images:
        try:
            w, h = png_size(png)
        except ValueError:
            w = h = 256
        tokens += image_tokens(w, h, detail)
    return ImageStats(images=len(images), image_bytes=sum(len(p) for p, _ in images), image_tokens=tokens)


def cache_view(message: Any) -> Any:
    """``message`` with each inline image replaced by ``sha256:<hex of its bytes>`` (for cache keys)."""
    parts = _parts(message.get("content"))
    if not parts:
        return message
    content = []
    for part in parts:
        png = _png_of(part)
        if png is None:
            content.append(part)
        else:
            digest = "sha256:" + hashlib.sha256(png).hexdigest()
            content.append({"type": "image_url", "image_url": {**part["image_url"], "url": digest}})
    return {**message, "content": content}
