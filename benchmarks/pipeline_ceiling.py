"""Benchmark: the ceiling our pipeline puts on a language planner, ``grounded`` vs the privileged ``oracle``.

``grounded`` knows the goal like an ideal language model but sees the world only through the
scene graph and subpolicies; the oracle reads the world. Both run through the evaluation harness
(``more_agent.eval.harness.evaluate``) over each task set and seed, into resumable run folders under
``--out`` (``<out>/<task set>/<planner>``, with summary.md holding the failure-cause table).

Prints one JSON line per (task set, planner): n, SR and TP in percent, failures per cause
(docs/evaluation.md), reach failures on observed targets ("no path on the map", "the way is
blocked", ...) per 100 high-level steps, the planner's median plan time per step in ms, and SR on
the episodes whose description singles out every goal instance (``WorldStats.ambiguous_scopes``
empty: no reader can beat chance on the others, docs/tasks.md); then one line per task set with
the SR and TP gaps, overall and on those episodes. It reads the worlds only through the harness, so it
runs unchanged on other worlds. Run:
``python benchmarks/pipeline_ceiling.py [--task-sets more-paper behavior-rearrange] [--seeds 3] [--first-seed 0] [--workers 2] [--limit N]
[--start random|random-area|task-room] [--no-distractors] [--descriptions named paper] [--perception gt|noisy[:K=V,...]]
[--sensing 1m/45deg]`` (run folders ``<out>/<start>[-no-distractors][/<perception>][/sensing-<cadence>]/descriptions-<mode>/<task set>/<planner>``,
the perception part only when not ``gt``, the sensing part only when not the default; the oracle reads no description and runs in the first mode only). Each line also gives TTC and rTP, and the description modes of its records.
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

from more_agent import __version__
from more_agent.errors import UserError
from more_agent.eval.failure import cause_counts, is_reach_failure
from more_agent.eval.harness import evaluate
from more_agent.eval.metrics import MetricSummary, summarize
from more_agent.eval.report import SourcedRecord
from more_agent.eval.report_writer import write_reports
from more_agent.eval.store import RunConfig, perception_part, sensing_part
from more_agent.perception_spec import GT, parse_perception
from more_agent.records import EpisodeRecord
from more_agent.sensing_spec import DEFAULT_SENSING, parse_sensing
from more_agent.sim.descriptions import DESCRIPTION_MODES
from more_agent.sim.tasks import task_set

PLANNERS = ("grounded", "oracle")


def unambiguous(records: list[EpisodeRecord]) -> list[EpisodeRecord]:
    """The episodes whose description singles out every instance the goal names."""
    return [r for r in records if r.world_stats is not None and not r.world_stats.ambiguous_scopes]


def row(task_set_name: str, planner: str, records: list[EpisodeRecord], s: MetricSummary, clear: MetricSummary) -> dict[str, object]:
    """The JSON line of one (task set, planner), with its summaries over all episodes and the unambiguous ones."""
    steps = sum(r.high_level_steps for r in records)
    reach = sum(is_reach_failure(a) for r in records for a in r.actions)
    plan_ms = [1000 * r.timings.get("plan", 0.0) / r.high_level_steps for r in records if r.high_level_steps]
    return {
        "task_set": task_set_name, "planner": planner, "n": s.n, "errors": s.n_errors,
        "descriptions": sorted({r.descriptions for r in records}),
        "sr": _pct(s.SR.mean), "ttc": _pct(s.TTC.mean), "tp": _pct(s.TP.mean),
        "rtp": _pct(s.rTP.mean) if s.rTP is not None else None,
        "n_unambiguous": clear.n, "sr_unambiguous": round(100 * clear.SR.mean, 1) if clear.n else None,
        "successes_per_seed": {seed: sum(r.success for r in records if r.seed == seed)
                               for seed in sorted({r.seed for r in records})},
        "high_level_steps": steps,
        "causes": dict(sorted(cause_counts(records).items())),
        "reach_failures_per_100_steps": round(100 * reach / steps, 2) if steps else None,
        "median_plan_ms_per_step": round(statistics.median(plan_ms), 3) if plan_ms else None,
    }


def _pct(x: float | None) -> float | None:
    return None if x is None else round(100 * x, 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task-sets", nargs="+", default=["more-paper", "behavior-rearrange"])
    parser.add_argument("--seeds", type=int, default=3, help="how many seeds of every task, from --first-seed")
    parser.add_argument("--first-seed", type=int, default=0, help="the first seed (re-measure on unseen seeds)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--limit", type=int, default=None, help="only the first N tasks of each set")
    parser.add_argument("--out", type=Path, default=Path("runs/pipeline_ceiling"))
    parser.add_argument("--planners", nargs="+", default=list(PLANNERS))
    parser.add_argument("--start", default="random", choices=["random", "random-area", "task-room"],
                        help="robot start of every episode (task-room: the worlds before random starts)")
    parser.add_argument("--distractors", action=argparse.BooleanOptionalAction, default=True,
                        help="add the scenes' own small objects (--no-distractors with --start task-room: the worlds "
                             "before the harder-worlds issue, scene still drawn per seed)")
    parser.add_argument("--descriptions", nargs="+", default=list(DESCRIPTION_MODES), choices=DESCRIPTION_MODES,
                        help="description modes (sim.descriptions); the oracle reads none, so it runs once")
    parser.add_argument("--perception", default=GT, help="'gt' or 'noisy[:KEY=VALUE,...]' (docs/sensors.md#noisy-perception)")
    parser.add_argument("--sensing", default=DEFAULT_SENSING, help="'DISTANCEm/ANGLEdeg' (docs/sensors.md#sensing-cadence)")
    args = parser.parse_args()
    try:
        perception = parse_perception(args.perception).text()
        sensing = parse_sensing(args.sensing).text()
    except UserError as e:
        parser.error(str(e))

    worlds = args.start if args.distractors else f"{args.start}-no-distractors"
    if perception != GT:
        worlds = f"{worlds}/{perception_part(perception)}"
    if sensing != DEFAULT_SENSING:
        worlds = f"{worlds}/{sensing_part(sensing)}"
    for name in args.task_sets:
        tasks = task_set(name)[: args.limit]
        for mode in args.descriptions:
            results: dict[str, tuple[MetricSummary, MetricSummary]] = {}
            for planner in args.planners:
                reads_description = planner != "oracle"
                run_mode = mode if reads_description else args.descriptions[0]
                config = RunConfig(
                    planner=planner, tasks=tasks, seeds=list(range(args.first_seed, args.first_seed + args.seeds)),
                    episode_fn="more_agent.eval.episode:run_episode", workers=args.workers, start=args.start,
                    distractors=args.distractors, descriptions=run_mode, perception=perception, sensing=sensing,
                    more_agent_version=__version__,
                )
                run_dir = args.out / worlds / f"descriptions-{run_mode}" / name / planner
                records = evaluate(config, run_dir, resume=run_dir.exists(), show_progress=False)
                write_reports([SourcedRecord(r, run_dir) for r in records], run_dir, title=f"{planner} on {name}")
                results[planner] = summarize(records), summarize(unambiguous(records))
                print(json.dumps(row(name, planner, records, *results[planner])), flush=True)
            if set(PLANNERS) <= set(results):
                (g, gc), (o, oc) = results["grounded"], results["oracle"]
                print(json.dumps({
                    "task_set": name, "descriptions": mode, "sr_gap": _pct(o.SR.mean - g.SR.mean),
                    "tp_gap": _pct(o.TP.mean - g.TP.mean), "sr_gap_unambiguous": _pct(oc.SR.mean - gc.SR.mean),
                }), flush=True)


if __name__ == "__main__":
    main()
