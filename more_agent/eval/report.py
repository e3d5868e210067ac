"""Reports of evaluation runs: Table I (summary.md), per-task tables, summary.csv, report.html, the
comparison plots (``more_agent.eval.report_plots``); merging runs.

Rows of Table I are systems (planner, plus LLM when there is one); every cell is the mean in percent
with its 95% interval; n and the number of errored episodes are their own columns.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from html import escape
from pathlib import Path
from typing import NamedTuple

from more_agent.errors import UserError
from more_agent.eval.failure import CAUSE_ORDER, cause_counts
from more_agent.eval.metrics import (
    METRIC_NAMES,
    Estimate,
    MetricSummary,
    by_system,
    by_task,
    group_by,
    summarize,
    system_label,
    wilson_interval,
)
from more_agent.eval.store import EPISODES_FILE, read_records
from more_agent.records import EpisodeRecord, FailureReason
from more_agent.redaction import for_terminal

SUMMARY_MD = "summary.md"
SUMMARY_CSV = "summary.csv"
REPORT_HTML = "report.html"
ALL_TASKS = "ALL"
"""Task column value of the overall rows in summary.csv."""
ALL_TRIALS = "ALL"
"""Trial column value of the summary.csv rows over every trial."""


class SourcedRecord(NamedTuple):
    """A record and the run directory it was read from (for per-episode files such as map.png)."""

    record: EpisodeRecord
    run_dir: Path


def load_runs(run_dirs: Sequence[Path]) -> tuple[list[SourcedRecord], int]:
    """Records of several runs merged, and how many duplicates were dropped (first run wins).

    Duplicates are records with the same (task, scene, seed, planner, trial, llm).
    """
    seen: set[tuple[str, str, int, str, int, str | None]] = set()
    out: list[SourcedRecord] = []
    dropped = 0
    for d in map(Path, run_dirs):
        if not (d / EPISODES_FILE).is_file():
            raise UserError(f"{d} is not an evaluation run (no {EPISODES_FILE})")
        for r in read_records(d / EPISODES_FILE):
            key = (*r.key(), r.llm)
            if key in seen:
                dropped += 1
                continue
            seen.add(key)
            out.append(SourcedRecord(r, d))
    return out, dropped


NO_VALUE = "n/a"
"""Shown for an rTP that no episode of the group has."""


def fmt(e: Estimate | None) -> str:
    """'48.1 [40.2, 55.3]': mean and 95% interval in percent; 'n/a' for None."""
    return NO_VALUE if e is None else f"{100 * e.mean:.1f} [{100 * e.low:.1f}, {100 * e.high:.1f}]"


def md_text(text: str) -> str:
    """Record text (a model name, a task name) made inert in Markdown: HTML and pipes escaped,
    credentials masked, escape sequences dropped (the tables are printed to the terminal too)."""
    return escape(for_terminal(text), quote=False).replace("|", "\\|")


def _md_table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(md_text(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def metric_cells(s: MetricSummary) -> list[str]:
    """The metric cells of a row; an estimate over fewer episodes than the row's (rTP) says its n."""
    estimates: list[Estimate | None] = [getattr(s, m) for m in METRIC_NAMES]
    return [fmt(e) + (f" (n={e.n})" if e is not None and e.n != s.n else "") for e in estimates]


def table_i_markdown(records: Sequence[EpisodeRecord]) -> str:
    """Table I: one row per system, SR / TTC / TP / rTP in percent with 95% intervals."""
    header = ["System", "n", "tasks", "errors", *(f"{m} [%]" for m in METRIC_NAMES)]
    rows = [[k, str(s.n), str(s.n_tasks), str(s.n_errors), *metric_cells(s)] for k, s in by_system(records).items()]
    return _md_table(header, rows)


def per_task_markdown(records: Sequence[EpisodeRecord]) -> str:
    """One row per (system, task)."""
    header = ["System", "Task", "n", "errors", *(f"{m} [%]" for m in METRIC_NAMES)]
    rows = [[k, t, str(s.n), str(s.n_errors), *metric_cells(s)] for (k, t), s in by_task(records).items()]
    return _md_table(header, rows)


def failure_markdown(records: Sequence[EpisodeRecord]) -> str:
    """Failure causes per system: episodes per cause (docs/evaluation.md), columns for the causes that occur."""
    groups = group_by(records, system_label)
    counts = {k: cause_counts(v) for k, v in groups.items()}
    causes = [c for c in CAUSE_ORDER if any(c in n for n in counts.values())]
    header = ["System", "n", "failures", *causes]
    rows = [
        [k, str(len(groups[k])), str(sum(n.values())), *(str(n.get(c, 0)) for c in causes)] for k, n in counts.items()
    ]
    return _md_table(header, rows)


def llm_markdown(records: Sequence[EpisodeRecord]) -> str:
    """LLM traffic per system with an LLM: calls, tokens, and the share of steps whose answer stayed invalid
    after its re-asks (an ``invalid`` action, reason ``invalid_answer``)."""
    header = ["System", "n", "LLM calls", "calls / episode", "prompt tokens", "completion tokens", "reasoning tokens"]
    header.append("invalid answers [% of steps]")
    rows = []
    for k, group in group_by((r for r in records if r.llm), system_label).items():
        usage = [r.llm_usage for r in group]
        steps = [a for r in group for a in r.actions]
        invalid = sum(a.reason is FailureReason.INVALID_ANSWER for a in steps)
        calls = sum(u.calls for u in usage)
        rows.append(
            [
                k,
                str(len(group)),
                str(calls),
                f"{calls / len(group):.1f}",
                str(sum(u.prompt_tokens for u in usage)),
                str(sum(u.completion_tokens for u in usage)),
                str(sum(u.reasoning_tokens for u in usage)),
                f"{100 * invalid / len(steps):.1f} ({invalid}/{len(steps)})" if steps else NO_VALUE,
            ]
        )
    return _md_table(header, rows)


def trials_markdown(records: Sequence[EpisodeRecord]) -> str:
    """SR and TP per system and trial (``eval --trials``; trials count from 0), and per system the share of
    worlds (task, scene, seed) that some trial solved ('any')."""
    header = ["System", "trial", "n", "SR [%]", "TP [%]"]
    rows = []
    for k, group in group_by(records, system_label).items():
        for trial, recs in sorted(group_by(group, lambda r: f"{r.trial:06d}").items()):
            s = summarize(recs)
            rows.append([k, str(int(trial)), str(s.n), fmt(s.SR), fmt(s.TP)])
        worlds = group_by(group, lambda r: f"{r.task}|{r.scene}|{r.seed}")
        solved = [any(r.success for r in w) for w in worlds.values()]
        low, high = wilson_interval(sum(solved), len(solved))
        any_sr = Estimate(mean=sum(solved) / len(solved), low=low, high=high, n=len(solved), method="wilson")
        rows.append([k, "any", str(len(solved)), fmt(any_sr), ""])
    return _md_table(header, rows)


def has_trials(records: Sequence[EpisodeRecord]) -> bool:
    """Whether ``records`` hold more than one trial of a world."""
    return any(r.trial > 0 for r in records)


TABLE_I_CAVEATS = (
    "Where this setting differs from the paper's (docs/evaluation.md): the VLM of the BUMBLE rows sees our "
    "renderer's flat-shaded boxes, each category in a colour from a hash of its name, not OmniGibson's "
    "photorealistic frames; BUMBLE's frame captions and object lists carry the scene graph's ground-truth "
    "names, states and relations, which matches the paper's ground-truth semantics but not what BUMBLE's VLM "
    "saw (it had to recognise objects in the image); manipulation is the paper's magic actions, within "
    "1.5 m of a reachable pose. Measured on the planner that knows the goal (20 paper tasks): labels that are "
    "not ground truth cost the pipeline's ceiling 10 SR points with 5% of them confused, 40 with every kind "
    "of perception error (docs/benchmarks.md); the renderer's and the captions' effect on BUMBLE's VLM are "
    "not measured (no capable VLM here)."
)
"""What a reader of Table I must know beside it (summary.md and report.html)."""


def summary_markdown(records: Sequence[EpisodeRecord], *, title: str = "Evaluation summary") -> str:
    """The whole summary.md: Table I, notes on the metrics, the per-task table."""
    return (
        "\n\n".join(
            [
                f"# {md_text(title)}",
                table_i_markdown(records),
                "Means in percent with 95% intervals: Wilson for SR and TTC, percentile bootstrap for TP and "
                "rTP. Episodes are weighted equally; errored episodes count as failures. rTP counts the goal "
                "conditions that name an observed task object; an episode that observed none has no rTP and "
                "leaves its mean (its n is then given).",
                TABLE_I_CAVEATS,
                *(["## Trials", trials_markdown(records)] if has_trials(records) else []),
                *(["## LLM traffic", llm_markdown(records)] if any(r.llm for r in records) else []),
                "## Failure causes",
                failure_markdown(records),
                "## Per task",
                per_task_markdown(records),
            ]
        )
        + "\n"
    )


def _csv_cells(e: Estimate | None) -> list[str]:
    """Mean, low and high of an estimate; empty cells for None."""
    return ["", "", ""] if e is None else [f"{v:.6f}" for v in (e.mean, e.low, e.high)]


def summary_csv(records: Sequence[EpisodeRecord]) -> str:
    """summary.csv: one row per system overall (task = 'ALL') and per (system, task), both over every
    trial (``trial`` = 'ALL'); with ``eval --trials``, also one overall row per (system, trial) after the
    system's overall row. ``n_rTP``: the episodes that have an rTP (empty rTP cells when none has)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(
        [
            "system",
            "task",
            "n",
            "n_tasks",
            "n_errors",
            *(f"{m}{s}" for m in METRIC_NAMES for s in ("", "_low", "_high")),
            "n_rTP",
            "trial",
        ]
    )
    rows: list[tuple[str, str, str, MetricSummary]] = []
    for system, group in group_by(records, system_label).items():
        rows.append((system, ALL_TASKS, ALL_TRIALS, summarize(group)))
        if has_trials(records):
            per_trial = group_by(group, lambda r: f"{r.trial:06d}")
            rows += [(system, ALL_TASKS, str(int(t)), summarize(v)) for t, v in sorted(per_trial.items())]
    rows += [(system, task, ALL_TRIALS, s) for (system, task), s in by_task(records).items()]
    for system, task, trial, s in rows:
        cells = [c for m in METRIC_NAMES for c in _csv_cells(getattr(s, m))]
        w.writerow([system, task, s.n, s.n_tasks, s.n_errors, *cells, s.rTP.n if s.rTP is not None else 0, trial])
    return buf.getvalue()
