"""Benchmark: what perception errors cost a planner (``--perception noisy``, docs/sensors.md#noisy-perception).

Runs one planner (default ``grounded``, the goal-aware planner; any planner and ``--llm`` a user passes)
through the evaluation harness on ``TASKS`` (20 of the paper's tasks: every second one of the
``more-paper`` set in its order), seed 0, under ground-truth perception, under each error kind alone
at its default rate, and under all kinds together; then SR against the rate for the two kinds that
cost most SR, at half, one and two times their default rate. Each condition is a resumable run folder
``<out>/<planner>/<perception>``; a later run with a larger ``--limit`` adds the missing tasks to the
same folders. Prints one JSON line per condition (n, SR / TP / rTP in percent, SR
points lost against gt, failures per cause), writes ``<out>/<planner>/table.md`` (the table of
docs/benchmarks.md) and ``<out>/<planner>/perception_noise.png`` (both figures). Run:
``nice -n 10 python benchmarks/perception_noise.py [--planner grounded] [--llm SPEC] [--workers 2]
[--limit N] [--seeds 1] [--no-sweep]``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from more_agent import __version__
from more_agent.eval.failure import CAUSE_ORDER, cause_counts
from more_agent.eval.harness import evaluate
from more_agent.eval.metrics import summarize
from more_agent.eval.store import RunConfig, perception_part
from more_agent.perception_spec import DEFAULTS, ERROR_KINDS, PerceptionSpec
from more_agent.records import EpisodeRecord
from more_agent.sim.tasks import task_set

TASKS = task_set("more-paper")[::2][:20]
"""Every second task of the paper's set, in its order: 20 tasks across its scenes."""

SWEEP_FACTORS = (0.5, 1.0, 2.0)
"""Rates of the sweep, as multiples of a kind's default."""


def run_condition(args: argparse.Namespace, perception: PerceptionSpec) -> list[EpisodeRecord]:
    """Every episode of one perception condition (resumed from its folder when it exists)."""
    text = perception.text()
    config = RunConfig(
        planner=args.planner,
        llm=args.llm,
        tasks=args.tasks,
        seeds=list(range(args.seeds)),
        episode_fn="more_agent.eval.episode:run_episode",
        workers=args.workers,
        perception=text,
        more_agent_version=__version__,
    )
    run_dir = args.out / args.planner / perception_part(text)
    records = evaluate(config, run_dir, resume=run_dir.exists(), allow_mixed=True, show_progress=False)
    return [r for r in records if r.task in args.tasks and r.seed < args.seeds]  # a folder grows with --limit


def row(name: str, records: list[EpisodeRecord], gt_sr: float | None) -> dict[str, object]:
    """The JSON line of one condition."""
    s = summarize(records)
    sr = round(100 * s.SR.mean, 1)
    return {
        "condition": name,
        "perception": records[0].perception if records else "",
        "n": s.n,
        "errors": s.n_errors,
        "sr": sr,
        "tp": round(100 * s.TP.mean, 1),
        "rtp": round(100 * s.rTP.mean, 1) if s.rTP else None,
        "sr_cost_points": None if gt_sr is None else round(gt_sr - sr, 1),
        "causes": dict(sorted(cause_counts(records).items())),
    }


def table(rows: list[dict[str, object]]) -> str:
    """The markdown table of the condition rows: metrics, then failures per cause (causes that occur)."""
    causes = [c for c in CAUSE_ORDER if any(c in r["causes"] for r in rows)]  # type: ignore[operator]
    head = ["condition", "perception", "n", "SR %", "TP %", "rTP %", "SR cost (points)", *causes]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r["condition"], f"`{r['perception']}`", r["n"], r["sr"], r["tp"], r["rtp"], r["sr_cost_points"]]
        cells += [r["causes"].get(c, 0) for c in causes]  # type: ignore[attr-defined]
        lines.append("| " + " | ".join("" if c is None else str(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def plot(rows: list[dict[str, object]], sweep: dict[str, list[tuple[float, float]]], path: Path) -> None:
    """SR per condition (bars) and SR against rate for the swept kinds (lines), one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [1.4, 1]})
    left.bar([str(r["condition"]) for r in rows], [float(r["sr"]) for r in rows], color="tab:blue")  # type: ignore[arg-type]
    left.set_ylabel("SR (%)")
    left.set_title("SR per perception condition")
    left.tick_params(axis="x", rotation=45)
    for kind, points in sweep.items():
        right.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=kind)
    right.set_xlabel("rate (kind's own unit, docs/sensors.md)")
    right.set_ylabel("SR (%)")
    right.set_title("SR against rate")
    right.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def step_time(task: str, steps: int) -> dict[str, object]:
    """CPU ms per sensed frame (render, perception, fusion into the map: all that noise adds to a step) with
    ground-truth and with all-kinds noisy perception, on the same motion: the initial full turn, then
    ``steps`` drives along shortest paths on the true map to seeded free cells, sensing every few moves as
    the subpolicies do. The two robots alternate drive by drive, so load from other jobs falls on both."""
    import time

    from more_agent.perception.model import NoisyPerception
    from more_agent.perception.robot import NoisyRobot
    from more_agent.planners.policies import Embodiment
    from more_agent.robot import Robot
    from more_agent.sim.env import SimRobot
    from more_agent.sim.instantiate import TaskInstance, instantiate
    from more_agent.sim.navgrid import free_cells, nav_grid
    from more_agent.sim.paths import shortest_path

    def robot(inst: TaskInstance, noisy: bool) -> Robot:
        sim = SimRobot(inst.world, labels=inst.labels)
        return NoisyRobot(sim, NoisyPerception(PerceptionSpec(mode="noisy"), inst.world, inst.labels, 0)) if noisy else sim

    bodies, spent, frames = {}, {"gt": 0.0, "noisy": 0.0}, {"gt": 0, "noisy": 0}
    for mode in spent:
        Embodiment(robot(instantiate(task, None, 1), mode == "noisy")).look_around()  # warm-up, untimed
        inst = instantiate(task, None, 0)
        world = inst.world
        body = bodies[mode] = Embodiment(robot(inst, mode == "noisy"))

        def timed(sense=body.sense, mode=mode, **kw: object) -> None:
            t = time.process_time()
            sense(**kw)
            spent[mode] += time.process_time() - t
            frames[mode] += 1

        body.sense = timed  # type: ignore[method-assign]
    grid = nav_grid(world)
    cells = free_cells(grid.free)
    paths, at = [], bodies["gt"].xy
    for c in cells[np.random.default_rng(0).permutation(len(cells))]:
        if len(paths) == steps:
            break
        path = shortest_path(grid, at, [grid.centre(tuple(c))])
        if path.found:
            paths.append([tuple(p) for p in path.waypoints])
            at = paths[-1][-1]
    for k in range(-1, len(paths)):
        for body in sorted(bodies.values(), key=lambda b: isinstance(b.robot, SimRobot) == (k % 2 == 0)):  # turns first
            if k < 0:
                body.look_around()
            else:
                body.follow(paths[k])
    assert bodies["gt"].trajectory == bodies["noisy"].trajectory and frames["gt"] == frames["noisy"]  # same frames
    gt, noisy = (1000 * spent[m] / frames[m] for m in ("gt", "noisy"))
    return {"task": task, "drives": len(paths), "frames": frames["gt"], "gt_ms_per_frame": round(gt, 2),
            "noisy_ms_per_frame": round(noisy, 2), "overhead_pct": round(100 * (noisy - gt) / gt, 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planner", default="grounded")
    parser.add_argument("--llm", default=None, help="LLM spec for LLM planners, e.g. 'openai:gpt-4o'")
    parser.add_argument("--seeds", type=int, default=1, help="seeds 0..N-1 of every task")
    parser.add_argument("--limit", type=int, default=None, help="only the first N of the 20 tasks")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("runs/perception_noise"))
    parser.add_argument("--sweep", action=argparse.BooleanOptionalAction, default=True, help="the rate sweep")
    parser.add_argument(
        "--step-time",
        type=int,
        metavar="ROUNDS",
        default=0,
        help="only time frames with noise on vs off (ROUNDS full turns each) and exit",
    )
    args = parser.parse_args()
    if args.step_time:
        print(json.dumps(step_time(TASKS[0], args.step_time)), flush=True)
        return
    args.tasks = TASKS[: args.limit]
    (args.out / args.planner).mkdir(parents=True, exist_ok=True)

    conditions = [("gt", PerceptionSpec()), ("all", PerceptionSpec(mode="noisy"))]
    conditions += [(k, PerceptionSpec().only(k)) for k in ERROR_KINDS]
    rows: list[dict[str, object]] = []
    for name, spec in conditions:
        rows.append(row(name, run_condition(args, spec), rows[0]["sr"] if rows else None))  # type: ignore[arg-type]
        print(json.dumps(rows[-1]), flush=True)
    (args.out / args.planner / "table.md").write_text(table(rows))
    sweep: dict[str, list[tuple[float, float]]] = {}
    if args.sweep:
        costliest = sorted(
            (r for r in rows if r["condition"] in ERROR_KINDS), key=lambda r: -float(r["sr_cost_points"])
        )  # type: ignore[arg-type]
        for r in costliest[:2]:
            kind = str(r["condition"])
            for factor in SWEEP_FACTORS:
                rate = min(1.0, DEFAULTS[kind] * factor)
                sr = float(row(kind, run_condition(args, PerceptionSpec().only(kind, rate)), None)["sr"])  # type: ignore[arg-type]
                sweep.setdefault(kind, []).append((rate, sr))
                print(json.dumps({"sweep": kind, "rate": rate, "sr": sr}), flush=True)
        (args.out / args.planner / "sweep.json").write_text(json.dumps(sweep, indent=1) + "\n")
    plot(rows, sweep, args.out / args.planner / "perception_noise.png")


if __name__ == "__main__":
    main()
