"""The episode viewer: one self-contained HTML file that steps through what the agent saw and thought.

``write_viewer(episode_dir)`` reads the files an episode leaves (``episode.json``, ``timeline.jsonl``,
and when present the LLM planner's ``steps.jsonl``, ``frames/`` from ``--save-frames`` and ``graphs/``
from ``--save-graph``) and writes ``viewer.html``: per high-level step the step's camera frames
(RGB and semantic, downscaled), the robot's map so far (occupancy, Voronoi graph by region,
frontiers, objects, path, the action's target), the full and the filtered scene text, every LLM
request and answer with tokens and latency, the action and its feedback, and the goal conditions met
so far (evaluation-only). Everything is inlined (data as JSON, images as data URIs); the page builds
its DOM with ``textContent`` so LLM text never becomes markup, and the JSON is escaped so that a
``</script>`` inside a string cannot end the script element.
"""

from __future__ import annotations

import base64
import io
import json
import logging
import re
from html import escape
from importlib.resources import files
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from more_agent.errors import UserError
from more_agent.eval.episode import run_episode
from more_agent.eval.episode_folder import EPISODE_FILE, EpisodeFolder, read_record
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.safe_files import read_bounded
from more_agent.sim.grid import Grid

log = logging.getLogger(__name__)

FRAMES_PER_STEP = 3
"""Camera frames shown per step: evenly spaced over the step, its last frame always among them."""
FRAME_PX = 128
"""Width and height of the embedded frames, in pixels (the camera renders 256 x 256)."""

_OCC_PALETTE = [0, 0, 0, 255, 255, 255, 64, 64, 64]
"""Occupancy cell value (unknown: transparent, free, occupied) -> colour on the map."""
_ITEM = re.compile(r",\s(?![^\[]*\])")
"""Separator of the objects on a scene-text line: a comma outside square brackets."""


def _data_uri(image: Image.Image, fmt: str) -> str:
    buf = io.BytesIO()
    image.save(buf, format=fmt, **({"quality": 80} if fmt == "JPEG" else {"compress_level": 1}))
    return f"data:image/{fmt.lower()};base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _frame_uris(folder: EpisodeFolder, index: int) -> dict[str, str] | None:
    """One frame's RGB (JPEG) and semantic (PNG) pictures, downscaled, as data URIs; None if missing."""
    out = {}
    for kind, fmt, resample in (
        ("rgb", "JPEG", Image.Resampling.BILINEAR),
        ("semantic", "PNG", Image.Resampling.NEAREST),
    ):
        path = folder.frame_path(index, kind)
        if not path.is_file():
            return None
        with Image.open(path) as im:
            out[kind] = _data_uri(im.convert("RGB").resize((FRAME_PX, FRAME_PX), resample), fmt)
    return out


def step_frame_indices(first: int, end: int, k: int = FRAMES_PER_STEP) -> list[int]:
    """Up to ``k`` frame indices evenly spread over ``[first, end)``, the last one included."""
    if end <= first:
        return []
    picks = np.linspace(end - 1, first, num=min(k, end - first)).round().astype(int)
    return sorted({int(i) for i in picks})


def _occupancy_uri(path: Path) -> tuple[str, list[float]] | None:
    """The occupancy grid of :func:`~more_agent.viz.graph_plot.occupancy_png` coloured (north up) as a
    palette PNG data URI, and its extent [x0, y0, x1, y1] in metres."""
    if not path.is_file():
        return None
    with Image.open(path) as im:
        origin, res = json.loads(im.text["origin_xy"]), float(im.text["resolution_m"])  # type: ignore[attr-defined]
        width, height = im.size  # the file's rows run along y from the lowest
        picture = im.transpose(Image.Transpose.FLIP_TOP_BOTTOM)
    picture.putpalette(_OCC_PALETTE)
    extent = Grid(origin_xy=tuple(origin), resolution_m=res).bounds((width, height))
    buf = io.BytesIO()
    picture.save(buf, format="PNG", transparency=0)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii"), [round(v, 3) for v in extent]


def _map(folder: EpisodeFolder, step: int) -> dict[str, Any] | None:
    """The robot's map of one step for the page: regions, Voronoi graph, frontiers, objects, robot."""
    graph_json = folder.graph_path(step)
    if not graph_json.is_file():
        return None
    g = json.loads(graph_json.read_text(encoding="utf-8"))
    nav = g["nav"]
    regions = sorted(g["regions"].values(), key=lambda r: r["id"])
    out: dict[str, Any] = {
        "nodes": [[round(x, 2), round(y, 2)] for x, y in nav["node_xy"]],
        "edges": nav["edges"],
        "doors": nav["door_edges"],
        "node_region": nav["node_region"],
        "regions": [
            {
                "id": r["id"],
                "label": r["room_label"],
                "frontiers": [[round(x, 2), round(y, 2)] for x, y in r["frontiers"]],
            }
            for r in regions
        ],
        "objects": [
            {
                "label": o["label"],
                "door": o["category"] == "door",
                "held": o["held"],
                "box": [round(v, 2) for v in (*o["bbox"]["min"][:2], *o["bbox"]["max"][:2])],
            }
            for o in g["objects"].values()
        ],
        "robot": [round(v, 2) for v in g["robot"]["position"]],
    }
    occ = _occupancy_uri(folder.graph_path(step, "_occupancy.png"))
    if occ is not None:
        out["occupancy"], out["extent"] = occ
    return out


def scene_segments(full: str, kept: str) -> list[list[list[Any]]]:
    """The full scene text as lines of [text, kept] pieces: a line's head (room) and each object on it
    are kept when the planning text has them under the same room; what the filter removed is False."""
    kept_lines: dict[str, set[str]] = {}
    for line in kept.splitlines():
        head, _, body = line.partition(": ")
        kept_lines[head] = set(_ITEM.split(body)) if body else set()
    verbatim = set(kept.splitlines())
    out = []
    for line in full.splitlines():
        if line in verbatim:
            out.append([[line, True]])
            continue
        head, sep, body = line.partition(": ")
        room_kept = head in kept_lines
        pieces: list[list[Any]] = [[head + sep, room_kept]]
        items = _ITEM.split(body) if body else []
        for i, item in enumerate(items):
            pieces.append([item + (", " if i < len(items) - 1 else ""), room_kept and item in kept_lines[head]])
        out.append(pieces)
    return out


def _read_jsonl(path: Path) -> list[dict[str, Any]]:
    """The step lines of ``timeline.jsonl`` or ``steps.jsonl``; a torn or foreign line is a UserError naming it."""
    if not path.is_file():
        return []
    lines = []
    for n, line in enumerate(read_bounded(path, what="step log").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            value = json.loads(line)
        except (ValueError, RecursionError):
            raise UserError(f"{path}: line {n} is not JSON (a torn or edited file); re-run the episode") from None
        if not isinstance(value, dict) or not isinstance(value.get("step"), int):
            raise UserError(f"{path}: line {n} is not a step line (no integer 'step')")
        lines.append(value)
    return lines


def _thumbnail(url: str) -> str:
    """An image data URI of a VLM request shrunk to a ``FRAME_PX`` JPEG thumbnail; '' if it is not one."""
    head, sep, data = url.partition(";base64,")
    if not (sep and head.startswith("data:image/")):
        return ""
    try:
        with Image.open(io.BytesIO(base64.b64decode(data))) as im:
            im.thumbnail((FRAME_PX, FRAME_PX))
            return _data_uri(im.convert("RGB"), "JPEG")
    except (OSError, ValueError):
        return ""


def _with_thumbnails(exchange: dict[str, Any]) -> dict[str, Any]:
    """The exchange with the images of its messages (VLM requests) as thumbnails, so pages stay small."""
    messages = []
    for m in exchange["messages"]:
        if isinstance(m.get("content"), list):
            m = {
                **m,
                "content": [
                    {**p, "image_url": {"url": _thumbnail(p.get("image_url", {}).get("url", ""))}}
                    if p.get("type") == "image_url"
                    else p
                    for p in m["content"]
                ],
            }
        messages.append(m)
    return {**exchange, "messages": messages}


def _llm_step(line: dict[str, Any] | None) -> dict[str, Any]:
    """The planner's part of a step (scene texts, exchanges, token and latency sums); {} without one."""
    if not line:
        return {}
    exchanges = [_with_thumbnails(x) for x in line.get("exchanges") or []]
    out: dict[str, Any] = {
        "exchanges": exchanges,
        "tokens": sum(e["prompt_tokens"] + e["completion_tokens"] for e in exchanges),
        "latency_s": round(sum(e["latency_s"] for e in exchanges), 3),
        "robot_room": line.get("robot_room"),
    }
    if line.get("scene") is not None:
        planning = line.get("planning_scene") or line["scene"]
        out["scene"] = scene_segments(line["scene"], planning)
        out["filtered"] = planning != line["scene"]
        out["planning_scene"] = planning
    return out


def viewer_data(episode_dir: Path) -> dict[str, Any]:
    """Everything the page shows, as one JSON-ready dict."""
    folder = EpisodeFolder(Path(episode_dir))
    if not folder.record_path.is_file():
        raise UserError(f"{episode_dir} is not an episode folder (no {EPISODE_FILE}); 'more-agent run' writes one")
    record = read_record(folder.record_path)
    timeline = {t["step"]: t for t in _read_jsonl(folder.timeline_path)}
    llm_steps = {s["step"]: s for s in _read_jsonl(folder.steps_path)}
    steps, first_frame = [], 0
    for action in record.actions:
        t = timeline.get(action.step, {})
        end_frame = t.get("frames", first_frame)
        picks = step_frame_indices(first_frame, end_frame)
        frames = [{"index": i, **f} for i in picks if (f := _frame_uris(folder, i))]
        steps.append(
            {
                "step": action.step,
                "action": action.model_dump(),
                "frames": frames,
                "frame_range": [first_frame, end_frame],
                "goals": t.get("goals"),
                "progress": t.get("progress"),
                "path_len": t.get("path_len"),
                "targets": t.get("targets", []),
                "map": _map(folder, action.step),
                **_llm_step(llm_steps.get(action.step)),
            }
        )
        first_frame = end_frame
    return {
        "record": record.model_dump(exclude={"actions", "trajectory", "traceback"}),
        "trajectory": [[round(x, 2), round(y, 2)] for x, y in record.trajectory],
        "steps": steps,
        "has_frames": folder.frames_dir.is_dir(),
    }


def safe_json(data: Any) -> str:
    """JSON that can sit inside a <script> element: '<', '>' and '&' escaped, so no string can close it."""
    text = json.dumps(data, ensure_ascii=True, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def render_viewer(data: dict[str, Any]) -> str:
    """The HTML page for ``viewer_data``'s dict."""
    r = data["record"]
    title = f"{r['task']} | {r['scene']} | seed {r['seed']} | {r['planner']}" + (f" ({r['llm']})" if r["llm"] else "")
    template = files("more_agent.eval").joinpath("templates/viewer.html").read_text(encoding="utf-8")
    return template.replace("__TITLE__", escape(title)).replace("__DATA__", safe_json(data))


def write_viewer(episode_dir: Path, out: Path | None = None) -> Path:
    """Write the viewer of ``episode_dir`` to ``out`` (default ``episode_dir/viewer.html``); return its path.

    Files that are JSON but not what this version writes (an edited or foreign step line) are a
    UserError naming the folder, as torn ones are."""
    try:
        data = viewer_data(Path(episode_dir))
    except (KeyError, TypeError, IndexError) as e:
        raise UserError(
            f"{episode_dir}: a step file holds a line this version cannot read ({type(e).__name__}: {e})"
        ) from None
    return EpisodeFolder(Path(episode_dir)).write_viewer(render_viewer(data), out)


def run_episode_with_viewer(spec: EpisodeSpec, *, out_dir: Path | None = None, **kwargs: Any) -> EpisodeRecord:
    """:func:`~more_agent.eval.episode.run_episode` with ``viewer=True``, then ``out_dir/viewer.html``
    (``run --viewer``, ``eval --viewer``); a page that cannot be written is logged, never costs the record."""
    record = run_episode(spec, out_dir=out_dir, viewer=True, **kwargs)
    if out_dir is not None:
        try:
            write_viewer(Path(out_dir))
        except Exception as e:  # noqa: BLE001 - a failed page must not lose the record or change its outcome
            log.warning("could not write the viewer of %s: %s: %s", out_dir, type(e).__name__, e)
    return record
