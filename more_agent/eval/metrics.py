"""Table I metrics (SR, TTC, TP, rTP) as pure functions of ``EpisodeRecord`` lists, with 95% CIs.

Per-episode values:

- SR: ``record.success`` (all goal conditions met and ``done()`` called).
- TTC: ``record.all_goals_met`` (all met, whether or not ``done()`` was called).
- TP: ``record.task_progress`` (share of goal conditions met).
- rTP: share of met conditions among the *observed* ones. The paper (Sec. IV-A): "share of
  completed goal conditions that include observed task objects": a condition is observed when at
  least one instance in its ``objects`` is in ``record.observed_objects`` (a condition that names no
  object counts as observed); the others leave the denominator. Requiring *every* instance would
  never count a condition on a floor or room fixture, which the robot does not observe as an object
  (see docs/evaluation.md, "rTP"). An episode that observed none of its conditions (or has none) has
  no rTP (None): it leaves the rTP mean, whose n is then the number of episodes that have one.

rTP is never stored: it is computed from each record's per-condition data (``goal_conditions``,
``observed_objects``), which every record version holds, so records of older versions get this
rule too.

Episodes that raised (``record.error`` set) are kept: they count as failures with the values their
record holds (the harness writes zeros). Aggregates are episode-weighted (each episode counts once;
with equal seeds per task this equals the mean over tasks of the per-task means).

Intervals: Wilson score for the rates SR and TTC; percentile bootstrap (seeded, deterministic)
for the means TP and rTP.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import Literal

import numpy as np
from pydantic import Field

from more_agent.records import EpisodeRecord, FrozenModel

Z_95 = 1.959963984540054
"""Two-sided 95% normal quantile."""

BOOTSTRAP_RESAMPLES = 2000
"""Bootstrap resamples for the TP / rTP intervals."""

METRIC_NAMES = ("SR", "TTC", "TP", "rTP")


def sr(record: EpisodeRecord) -> float:
    """Success: all goal conditions met and done() called."""
    return 1.0 if record.success else 0.0


def ttc(record: EpisodeRecord) -> float:
    """Total task completion: all goal conditions met, done() or not."""
    return 1.0 if record.all_goals_met else 0.0


def tp(record: EpisodeRecord) -> float:
    """Task progression: share of goal conditions met."""
    return float(record.task_progress)


def rtp(record: EpisodeRecord) -> float | None:
    """Relative task progression: share of met conditions among those that include an observed task object.

    None when no condition was observed: the episode has no rTP (see the module docstring).
    """
    seen = set(record.observed_objects)
    observed = [c for c in record.goal_conditions if not c.objects or any(o in seen for o in c.objects)]
    if not observed:
        return None
    return sum(c.satisfied for c in observed) / len(observed)


PER_EPISODE: dict[str, Callable[[EpisodeRecord], float | None]] = {"SR": sr, "TTC": ttc, "TP": tp, "rTP": rtp}
"""Metric name -> per-episode value function (None: the episode has no value of that metric)."""


class Estimate(FrozenModel):
    """A mean over the episodes that have a value of the metric, with its 95% confidence interval."""

    mean: float = Field(description="Mean over episodes, in [0, 1].")
    low: float = Field(description="Lower end of the 95% interval.")
    high: float = Field(description="Upper end of the 95% interval.")
    n: int = Field(description="Episodes with a value (each has an SR, TTC and TP; not each an rTP).")
    method: Literal["wilson", "bootstrap"] = Field(description="How the interval was computed.")


class MetricSummary(FrozenModel):
    """The four Table I metrics over one group of episodes, plus counts."""

    n: int = Field(description="Episodes in the group.")
    n_tasks: int = Field(description="Distinct tasks in the group.")
    n_errors: int = Field(description="Episodes that ended with an error (counted as failures).")
    SR: Estimate
    TTC: Estimate
    TP: Estimate
    rTP: Estimate | None = Field(
        description="None when no episode of the group has an rTP (none saw a goal condition)."
    )


def wilson_interval(successes: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion; (0, 1) when n == 0."""
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def bootstrap_interval(
    values: Sequence[float], *, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = 0
) -> tuple[float, float]:
    """Percentile bootstrap 95% interval of the mean; (0, 1) for no values. Independent of value order."""
    x = np.sort(np.asarray(values, dtype=float))
    if x.size == 0:
        return 0.0, 1.0
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(resamples, x.size))].mean(axis=1)
    low, high = np.quantile(means, [0.025, 0.975])
    return float(low), float(high)


def estimate(records: Sequence[EpisodeRecord], metric: str) -> Estimate:
    """Mean and 95% interval of one metric ('SR', 'TTC', 'TP', 'rTP') over the ``records`` that have a value."""
    values = sorted(v for r in records if (v := PER_EPISODE[metric](r)) is not None)  # sorted: order-free
    n = len(values)
    mean = float(np.mean(values)) if n else 0.0
    if metric in ("SR", "TTC"):
        low, high = wilson_interval(int(round(sum(values))), n)
        return Estimate(mean=mean, low=low, high=high, n=n, method="wilson")
    low, high = bootstrap_interval(values)
    return Estimate(mean=mean, low=low, high=high, n=n, method="bootstrap")


def summarize(records: Sequence[EpisodeRecord]) -> MetricSummary:
    """All four metrics with intervals and counts over one group of episodes."""
    return MetricSummary(
        n=len(records),
        n_tasks=len({r.task for r in records}),
        n_errors=sum(r.error is not None for r in records),
        **{m: estimate(records, m) for m in METRIC_NAMES if m != "rTP"},
        rTP=estimate(records, "rTP") if any(rtp(r) is not None for r in records) else None,
    )


class PairedSR(FrozenModel):
    """Two systems' successes on the same episodes (:func:`paired_sr`)."""

    n: int = Field(
        description="Episodes both systems ran (same task, scene, seed, trial, start, distractors, descriptions)."
    )
    both: int = Field(description="Solved by both.")
    only_a: int = Field(description="Solved by the first system only.")
    only_b: int = Field(description="Solved by the second system only.")
    neither: int = Field(description="Solved by neither.")
    p_value: float = Field(description="Exact two-sided McNemar test: the binomial test of only_a against only_b.")


def episode_key(record: EpisodeRecord) -> tuple[object, ...]:
    """What makes two records the same episode for two systems: the world and the task as posed."""
    return (record.task, record.scene, record.seed, record.trial, record.start, record.distractors, record.descriptions)


def paired_records(a: Sequence[EpisodeRecord], b: Sequence[EpisodeRecord]) -> list[tuple[EpisodeRecord, EpisodeRecord]]:
    """The episodes both ran (:func:`episode_key`), as (record of ``a``, record of ``b``), in ``b``'s order."""
    first = {episode_key(r): r for r in a}
    return [(first[k], r) for r in b if (k := episode_key(r)) in first]


def paired_sr(a: Sequence[EpisodeRecord], b: Sequence[EpisodeRecord]) -> PairedSR:
    """Compare two systems' SR on the episodes both ran. Their SRs are not independent samples: the same worlds
    are hard for both, so the test counts only the episodes one solves and the other does not (McNemar).
    On the default worlds about 7 % of episodes flip under a change that alters what the robot sees by a few
    cells (docs/benchmarks.md), so a few flips either way say nothing; the p-value says how many do."""
    from scipy.stats import binomtest

    pairs = [(x.success, y.success) for x, y in paired_records(a, b)]
    only_a = sum(x and not y for x, y in pairs)
    only_b = sum(y and not x for x, y in pairs)
    flips = only_a + only_b
    return PairedSR(
        n=len(pairs),
        both=sum(x and y for x, y in pairs),
        only_a=only_a,
        only_b=only_b,
        neither=sum(not x and not y for x, y in pairs),
        p_value=float(binomtest(only_a, flips).pvalue) if flips else 1.0,
    )


def system_label(record: EpisodeRecord) -> str:
    """Row label of a record's system in comparison tables: the planner, plus the LLM if any."""
    return f"{record.planner} ({record.llm})" if record.llm else record.planner


def group_by(records: Iterable[EpisodeRecord], key: Callable[[EpisodeRecord], str]) -> dict[str, list[EpisodeRecord]]:
    """Records grouped by ``key``, groups in sorted key order, records in input order."""
    groups: dict[str, list[EpisodeRecord]] = {}
    for r in records:
        groups.setdefault(key(r), []).append(r)
    return dict(sorted(groups.items()))


def by_system(records: Iterable[EpisodeRecord]) -> dict[str, MetricSummary]:
    """Overall metrics per system (planner + LLM): the rows of Table I."""
    return {k: summarize(v) for k, v in group_by(records, system_label).items()}


def by_task(records: Iterable[EpisodeRecord]) -> dict[tuple[str, str], MetricSummary]:
    """Metrics per (system, task)."""
    out: dict[tuple[str, str], MetricSummary] = {}
    for system, recs in group_by(records, system_label).items():
        for task, task_recs in group_by(recs, lambda r: r.task).items():
            out[(system, task)] = summarize(task_recs)
    return out
