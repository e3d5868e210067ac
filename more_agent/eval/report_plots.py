"""Comparison plots of evaluation runs, written as PNGs beside summary.md and linked from report.html.

- ``plot_metrics.png``: SR / TTC / TP / rTP per system with their 95% intervals (Table I as a plot);
- ``plot_tasks.png``: success rate per task and system as a heat map (tasks x systems);
- ``plot_distributions.png``: high-level steps and LLM tokens per episode, per system;
- ``plot_failures.png``: why unsuccessful episodes failed, counted per system.

Every function takes plain records and writes one file; systems are ordered as in Table I.
"""

from __future__ import annotations

import io
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from more_agent.eval.metrics import METRIC_NAMES, Estimate, by_system, by_task, group_by, system_label  # noqa: E402
from more_agent.records import EpisodeRecord  # noqa: E402
from more_agent.safe_files import write_atomic  # noqa: E402

PLOT_FILES = {
    "metrics": "plot_metrics.png",
    "tasks": "plot_tasks.png",
    "distributions": "plot_distributions.png",
    "failures": "plot_failures.png",
}
"""Plot name -> file name in the report folder."""

DPI = 100
_COLOURS = plt.get_cmap("tab10")
NO_ESTIMATE = Estimate(mean=0.0, low=0.0, high=0.0, n=0, method="bootstrap")
"""Drawn for a system without an rTP: no bar, 'n/a'."""


def _save(fig: plt.Figure, path: Path) -> Path:
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    finally:
        plt.close(fig)
    write_atomic(path, buf.getvalue(), durable=False)
    return path


def plot_metrics(records: Sequence[EpisodeRecord], path: Path) -> Path:
    """One panel per metric: a bar per system at its mean with the 95% interval as error bar."""
    systems = by_system(records)
    names = list(systems)
    fig, axes = plt.subplots(
        2, 2, figsize=(9, 2 * (0.9 + 0.4 * len(names)) + 0.6), sharey=True, constrained_layout=True
    )
    y = np.arange(len(names))
    for ax, metric in zip(axes.flat, METRIC_NAMES):
        est = [getattr(systems[n], metric) or NO_ESTIMATE for n in names]
        mean = np.array([100 * e.mean for e in est])
        # clipped at 0: a percentile bootstrap's interval can miss the mean of a tiny, skewed sample
        err = np.clip([[100 * (e.mean - e.low) for e in est], [100 * (e.high - e.mean) for e in est]], 0, None)
        ax.barh(y, mean, xerr=err, color=[_COLOURS(i % 10) for i in range(len(names))], capsize=3, alpha=0.85)
        for yi, m, e in zip(y, mean, est):
            ax.text(min(100 * e.high + 1.5, 92), yi, f"{m:.0f}" if e.n else "n/a", va="center", fontsize=8)
        ax.set_xlim(0, 100)
        ax.set_title(f"{metric} [%]", fontsize=10)
        ax.grid(axis="x", alpha=0.3)
        ax.set_yticks(y, [f"{n} (n={systems[n].n})" for n in names], fontsize=8)
    axes[0, 0].invert_yaxis()
    fig.suptitle("Means with 95% intervals (Wilson for SR/TTC, bootstrap for TP/rTP)", fontsize=9)
    return _save(fig, path)


def plot_task_heatmap(records: Sequence[EpisodeRecord], path: Path) -> Path:
    """Success rate per (task, system); blank where a system did not run a task."""
    cells = by_task(records)
    systems = list(group_by(records, system_label))
    tasks = sorted({t for _, t in cells})
    sr = np.full((len(tasks), len(systems)), np.nan)
    for (system, task), s in cells.items():
        sr[tasks.index(task), systems.index(system)] = 100 * s.SR.mean
    fig, ax = plt.subplots(figsize=(4.0 + 1.0 * len(systems), 1.6 + 0.2 * len(tasks)))
    im = ax.imshow(np.ma.masked_invalid(sr), cmap="RdYlGn", vmin=0, vmax=100, aspect="auto", interpolation="nearest")
    ax.set_xticks(range(len(systems)), systems, rotation=30, ha="left", fontsize=8)
    ax.set_yticks(range(len(tasks)), tasks, fontsize=7)
    ax.xaxis.tick_top()
    ax.tick_params(axis="x", labeltop=True, labelbottom=False)
    fig.colorbar(im, ax=ax, label="SR [%]", shrink=min(1.0, 8 / max(len(tasks), 1)) if len(tasks) > 8 else 1.0)
    ax.set_title("Success rate per task", fontsize=10, pad=60)
    return _save(fig, path)


def plot_distributions(records: Sequence[EpisodeRecord], path: Path) -> Path:
    """High-level steps and LLM tokens (prompt + completion) per episode, as box plots with the episodes as dots."""
    groups = group_by(records, system_label)
    names = list(groups)
    series = {
        "high-level steps per episode": [[r.high_level_steps for r in groups[n]] for n in names],
        "LLM tokens per episode": [
            [r.llm_usage.prompt_tokens + r.llm_usage.completion_tokens for r in groups[n]] for n in names
        ],
    }
    fig, axes = plt.subplots(1, 2, figsize=(max(8.0, 2.0 + 2.2 * len(names)), 4.2))
    rng = np.random.default_rng(0)
    for ax, (title, data) in zip(axes, series.items()):
        ax.boxplot(data, positions=range(len(names)), widths=0.5, showfliers=False)
        for i, values in enumerate(data):
            ax.scatter(
                i + rng.uniform(-0.18, 0.18, len(values)), values, s=8, alpha=0.5, color=_COLOURS(i % 10), zorder=3
            )
        ax.set_title(title, fontsize=10)
        ax.grid(axis="y", alpha=0.3)
        ax.set_xticks(range(len(names)), names, fontsize=8, rotation=20, ha="right")
    return _save(fig, path)


def failure_reason(record: EpisodeRecord) -> str | None:
    """Why an unsuccessful episode failed: its ``failure.cause`` when classified, else the kind of its
    system error ('llm error'), else how it ended ('step_limit'), else 'unclassified'; None for a success."""
    if record.success:
        return None
    if record.failure is not None:
        return record.failure.cause
    if record.error is not None:
        return f"{record.error_kind or 'system'} error"
    return record.termination or "unclassified"


def plot_failures(records: Sequence[EpisodeRecord], path: Path) -> Path:
    """Stacked bars: per system, its unsuccessful episodes split by failure reason."""
    groups = group_by(records, system_label)
    names = list(groups)
    counts = {n: Counter(c for r in groups[n] if (c := failure_reason(r)) is not None) for n in names}
    reasons = sorted({c for cnt in counts.values() for c in cnt}, key=lambda c: -sum(cnt[c] for cnt in counts.values()))
    fig, ax = plt.subplots(figsize=(9, 1.2 + 0.5 * len(names) + 0.25 * len(reasons)))
    left = np.zeros(len(names))
    cmap = plt.get_cmap("tab20")
    for k, reason in enumerate(reasons):
        widths = np.array([counts[n][reason] for n in names], dtype=float)
        ax.barh(range(len(names)), widths, left=left, color=cmap(k % 20), label=reason)
        left += widths
    ax.set_yticks(
        range(len(names)), [f"{n} ({int(left[i])} of {len(groups[n])})" for i, n in enumerate(names)], fontsize=8
    )
    ax.invert_yaxis()
    ax.set_xlabel("unsuccessful episodes")
    ax.set_title("Failure reasons per system" + ("" if reasons else ": no failures"), fontsize=10)
    if reasons:
        ax.legend(
            fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.25 - 0.1 * len(names) / 4), ncol=2, frameon=False
        )
    return _save(fig, path)


def write_plots(records: Sequence[EpisodeRecord], out_dir: Path) -> list[Path]:
    """All four plots into ``out_dir`` (nothing for no records); return their paths."""
    if not records:
        return []
    out_dir = Path(out_dir)
    return [
        plot_metrics(records, out_dir / PLOT_FILES["metrics"]),
        plot_task_heatmap(records, out_dir / PLOT_FILES["tasks"]),
        plot_distributions(records, out_dir / PLOT_FILES["distributions"]),
        plot_failures(records, out_dir / PLOT_FILES["failures"]),
    ]
