"""The HTML report of evaluation runs (``DIR/report.html``).

Table I, the comparison plots (PNG files beside it, shown as linked thumbnails), the per-task table,
then one collapsible section per episode: a map thumbnail, a link to the episode's viewer when it
has one (``eval --viewer``), goal conditions, the action trace with feedback, LLM usage and cost,
and any error. Pictures stay files the page links to (relative paths, loaded lazily), so the page
stays small for large runs: ``DIR/episodes/<key>/map.png`` when the episode wrote one, else the
trajectory alone as inline SVG. Every piece of record text is passed through ``html.escape``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from html import escape
from pathlib import Path
from urllib.parse import quote

from more_agent.eval.episode_folder import MAP_FILE, VIEWER_FILE
from more_agent.eval.metrics import METRIC_NAMES, MetricSummary, by_system, by_task, rtp, system_label
from more_agent.eval.report import NO_VALUE, TABLE_I_CAVEATS, SourcedRecord, metric_cells
from more_agent.eval.store import EPISODE_DIRS, episode_dir, episode_dirname
from more_agent.records import EpisodeRecord
from more_agent.sensing_spec import DEFAULT_SENSING

THUMB_PX = 160
"""Width and height of episode thumbnails, in CSS pixels."""

_STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;font-size:13px}
th{background:#f3f3f3}details{border:1px solid #ddd;margin:4px 0;padding:4px}
summary{cursor:pointer}.ok{color:#176317}.fail{color:#a11}.err{color:#a11;font-weight:bold}
.ep{display:flex;gap:1em;align-items:flex-start}.plots{display:flex;flex-wrap:wrap;gap:8px;align-items:flex-start}
img.plot{max-width:560px;max-height:420px;border:1px solid #ddd}pre{background:#f7f7f7;padding:6px;overflow-x:auto}
"""


def episode_file(record: EpisodeRecord, run_dir: Path, name: str) -> Path | None:
    """A file of the episode's folder under ``run_dir/episodes/``, looked up by resolved scene then 'auto'
    (and in the folders of runs written before the LLM, start and distractors, or the sensing cadence, were
    part of the name)."""
    unnamed_cadence = record.model_copy(update={"sensing": DEFAULT_SENSING})
    for scene in (record.scene or None, None):
        for folder in (
            episode_dir(run_dir, record, scene or "auto"),
            episode_dir(run_dir, unnamed_cadence, scene or "auto"),
            Path(run_dir) / EPISODE_DIRS / episode_dirname(record.task, scene, record.seed, record.planner),
        ):
            if (folder / name).is_file():
                return folder / name
    return None


def link(path: Path, base: Path) -> str:
    """``path`` relative to the folder ``base`` as an escaped URL for an href / src attribute."""
    return escape(quote(Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()))


def trajectory_svg(trajectory: Sequence[tuple[float, float]], *, size_px: int = THUMB_PX) -> str:
    """The path alone as an inline SVG polyline (start green, end red), y up; '' for no path."""
    if not trajectory:
        return ""
    xs, ys = [p[0] for p in trajectory], [p[1] for p in trajectory]
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1e-6)
    margin = 8.0
    scale = (size_px - 2 * margin) / span

    def xy(p: tuple[float, float]) -> tuple[float, float]:
        return margin + (p[0] - min(xs)) * scale, size_px - margin - (p[1] - min(ys)) * scale

    pts = " ".join(f"{x:.1f},{y:.1f}" for x, y in map(xy, trajectory))
    (x0, y0), (x1, y1) = xy(trajectory[0]), xy(trajectory[-1])
    return (
        f'<svg width="{size_px}" height="{size_px}" viewBox="0 0 {size_px} {size_px}" '
        f'style="background:#fafafa;border:1px solid #ccc"><title>{span:.1f} m across</title>'
        f'<polyline points="{pts}" fill="none" stroke="#1f5fbf" stroke-width="1.5"/>'
        f'<circle cx="{x0:.1f}" cy="{y0:.1f}" r="3" fill="#2a2"/><circle cx="{x1:.1f}" cy="{y1:.1f}" r="3" fill="#c22"/></svg>'
    )


def thumbnail_html(record: EpisodeRecord, run_dir: Path, base: Path) -> str:
    """The episode's map.png linked (relative to the report folder ``base``), else its trajectory as SVG,
    else a placeholder."""
    png = episode_file(record, run_dir, MAP_FILE)
    if png is not None:
        src = link(png, base)
        return f'<a href="{src}"><img alt="map" loading="lazy" width="{THUMB_PX}" src="{src}"></a>'
    return trajectory_svg(record.trajectory) or "<em>no trajectory</em>"


def _summary_table(rows: list[tuple[list[str], MetricSummary]], head: list[str]) -> str:
    th = "".join(f"<th>{escape(h)}</th>" for h in [*head, "n", "errors", *(f"{m} [%]" for m in METRIC_NAMES)])
    body = "".join(
        "<tr>"
        + "".join(f"<td>{escape(c)}</td>" for c in [*labels, str(s.n), str(s.n_errors)])
        + "".join(f"<td>{escape(cell)}</td>" for cell in metric_cells(s))
        + "</tr>"
        for labels, s in rows
    )
    return f"<table><tr>{th}</tr>{body}</table>"


def _status(r: EpisodeRecord) -> str:
    if r.error is not None:
        return '<span class="err">error</span>'
    cls, word = ("ok", "success") if r.success else ("fail", "goals met, no done()" if r.all_goals_met else "failed")
    return f'<span class="{cls}">{word}</span>'


def _percent(value: float | None) -> str:
    """'80%', or 'n/a' for no value."""
    return NO_VALUE if value is None else f"{100 * value:.0f}%"


def episode_html(r: EpisodeRecord, run_dir: Path, base: Path) -> str:
    """One episode's collapsible section; links are relative to the report folder ``base``."""
    viewer = episode_file(r, run_dir, VIEWER_FILE)
    viewer_link = f' | <a href="{link(viewer, base)}">viewer</a>' if viewer is not None else ""
    head = (
        f"{_status(r)} {escape(system_label(r))} | {escape(r.task)} | {escape(r.scene or '-')} | seed {r.seed} | "
        f"TP {100 * r.task_progress:.0f}% rTP {_percent(rtp(r))} | {r.high_level_steps} steps{viewer_link}"
    )
    conds = "".join(
        f'<li class="{"ok" if c.satisfied else "fail"}">{"&#10003;" if c.satisfied else "&#10007;"} {escape(c.text)}</li>'
        for c in r.goal_conditions
    )
    acts = "".join(
        f"<tr><td>{a.step}</td><td>{escape(a.name)}</td><td>{escape(', '.join(a.arguments))}</td>"
        f'<td class="{"ok" if a.ok else "fail"}">{"ok" if a.ok else "failed"}</td><td>{escape(a.feedback)}</td>'
        f"<td>{a.low_level_steps}</td></tr>"
        for a in r.actions
    )
    u = r.llm_usage
    usage = (
        f"LLM: {escape(r.llm or 'none')}, {u.calls} calls ({u.cache_hits} cached), "
        f"{u.prompt_tokens} prompt + {u.completion_tokens} completion tokens, ${u.cost_usd:.4f}"
    )
    err = ""
    if r.error is not None:
        err = f'<p class="err">{escape(r.error)}</p>' + (f"<pre>{escape(r.traceback)}</pre>" if r.traceback else "")
    return (
        f'<details><summary>{head}</summary><div class="ep"><div>{thumbnail_html(r, run_dir, base)}</div><div>'
        f"<p>{escape(r.description)}</p>{err}<p>{usage}</p><ul>{conds}</ul>"
        f"<table><tr><th>step</th><th>action</th><th>arguments</th><th>result</th><th>feedback</th>"
        f"<th>low-level</th></tr>{acts}</table></div></div></details>"
    )


def plots_html(plots: Sequence[Path], base: Path) -> str:
    """The plot files as linked thumbnails."""
    return "".join(
        f'<a href="{link(p, base)}"><img class="plot" alt="{escape(p.stem)}" src="{link(p, base)}"></a>' for p in plots
    )


def render_report(
    sourced: Sequence[SourcedRecord],
    *,
    title: str = "Evaluation report",
    out_dir: Path | None = None,
    plots: Sequence[Path] = (),
) -> str:
    """The whole HTML document, to be written into ``out_dir`` (links are relative to it; default the
    current folder)."""
    base = Path(out_dir) if out_dir is not None else Path.cwd()
    records = [s.record for s in sourced]
    cost = sum(r.llm_usage.cost_usd for r in records)
    calls = sum(r.llm_usage.calls for r in records)
    overall = _summary_table([([k], s) for k, s in by_system(records).items()], ["System"])
    tasks = _summary_table([([k, t], s) for (k, t), s in by_task(records).items()], ["System", "Task"])
    episodes = "\n".join(episode_html(s.record, s.run_dir, base) for s in sourced)
    return (
        f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{escape(title)}</title>'
        f"<style>{_STYLE}</style></head><body><h1>{escape(title)}</h1>"
        f"<p>{len(records)} episodes, {calls} LLM calls, ${cost:.2f}. Means in percent with 95% intervals "
        f'(Wilson for SR/TTC, bootstrap for TP/rTP).</p>{overall}<p class="caveats">{escape(TABLE_I_CAVEATS)}</p><div class="plots">{plots_html(plots, base)}</div>'
        f"<details><summary>Per task</summary>{tasks}</details><h2>Episodes</h2>\n{episodes}\n</body></html>\n"
    )
