"""Compare two runs on the episodes both ran: each SR, the paired counts and McNemar's p-value, and the flips.

    python scripts/compare_runs.py RUN_A RUN_B

Each RUN is an ``episodes.jsonl`` or the folder holding it (a planner's folder of a ``pipeline_ceiling`` or
``more-agent eval`` run, e.g. ``runs/x/random/descriptions-named/more-paper/grounded``). Two planners on the
same worlds, or one planner before and after a change: the same worlds are hard for both, so only the
episodes one solves and the other does not tell them apart (``metrics.paired_sr``). On the default worlds
about 7 % of episodes flip under a change that alters what the robot sees by a few cells
(docs/benchmarks.md): read a handful of flips as noise unless the p-value says otherwise. Each flip is
listed with both failure causes, to trace with ``scripts/trace_episode.py``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from more_agent.eval.metrics import estimate, paired_records, paired_sr
from more_agent.eval.store import read_records
from more_agent.records import EpisodeRecord


def outcome(record: EpisodeRecord) -> str:
    """'solved' or the failure cause."""
    if record.success:
        return "solved"
    return record.failure.cause if record.failure is not None else "failed"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run_a", type=Path)
    parser.add_argument("run_b", type=Path)
    args = parser.parse_args()
    a, b = read_records(args.run_a), read_records(args.run_b)
    if not a or not b:
        raise SystemExit(f"no episode records in {args.run_a if not a else args.run_b}")
    for name, records in (("A", a), ("B", b)):
        sr = estimate(records, "SR")
        print(f"{name}: SR {100 * sr.mean:.1f} % [{100 * sr.low:.1f}, {100 * sr.high:.1f}] over {sr.n} episodes")
    paired = paired_sr(a, b)
    print(
        f"paired over {paired.n} episodes: both {paired.both}, A only {paired.only_a}, B only {paired.only_b}, "
        f"neither {paired.neither}; McNemar p = {paired.p_value:.3g}"
    )
    for before, r in sorted(paired_records(a, b), key=lambda pair: (pair[1].task, pair[1].seed, pair[1].trial)):
        if before.success != r.success:
            print(f"  {r.task} seed {r.seed} ({r.scene}): {outcome(before)} -> {outcome(r)}")


if __name__ == "__main__":
    main()
