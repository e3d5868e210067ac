"""SmolLM2 (llama.cpp, in process) driving each planner for a few steps: time per step and names it got wrong.

A whole SmolLM2 episode runs up to 50 high-level steps of minutes each on a shared 2-core machine, so
each planner runs the first ``--steps`` steps of one episode (the runner's step limit lowered to
that), with name enums as ``--enums`` says (``MORE_AGENT_NAME_ENUMS``: ``auto`` gives llama.cpp the
per-request enums, by position for the planning answer; ``off`` none). Every request goes through a
fresh response cache, which is then read back: an answer was rejected when the next request of its
conversation is a re-ask (``That answer cannot be used: REASON``); it named an unknown or misplaced
name when REASON says ``unknown`` or an argument count is wrong. One JSON line per run: wall and CPU
seconds per step (CPU of this process, llama.cpp's one thread included), LLM calls, answers rejected
and for names, invalid steps, and the extrapolation to a full 50-step episode.

    python benchmarks/local_llm_steps.py --task bringing_water --planners more,moma-llm,bumble --enums auto,off --steps 2
"""

from __future__ import annotations

import argparse
import json
import os
import sqlite3
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from more_agent.eval import episode  # noqa: E402
from more_agent.eval.termination import MAX_HIGH_LEVEL_STEPS  # noqa: E402
from more_agent.llm.reask import REASK_TEMPLATE  # noqa: E402
from more_agent.records import EpisodeSpec  # noqa: E402

REASK = REASK_TEMPLATE.split("{", 1)[0]
NAME_REASONS = ("unknown", "argument(s), got", "takes ")
"""Phrases of a re-ask reason about names: an unknown room or object, a wrong number of arguments."""


def rejected_reasons(cache: Path) -> tuple[int, list[str]]:
    """Requests sent and the reasons of the answers that were re-asked, from the response cache."""
    with sqlite3.connect(cache) as db:
        requests = [json.loads(r) for (r,) in db.execute("SELECT request FROM responses")]
    reasons = []
    for request in requests:
        last = request["messages"][-1]["content"]
        if isinstance(last, str) and last.startswith(REASK):
            reasons.append(last[len(REASK) :].split("\n", 1)[0])
    return len(requests), reasons


def run(task: str, planner: str, enums: str, steps: int, seed: int) -> dict[str, Any]:
    """The first ``steps`` steps of one SmolLM2 episode of ``planner``; times and rejected names."""
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "cache.sqlite"
        os.environ.update(MORE_AGENT_NAME_ENUMS=enums, MORE_AGENT_LLM_CACHE=str(cache), MORE_AGENT_LLM_CACHE_MODE="on")
        episode.MAX_HIGH_LEVEL_STEPS = steps  # type: ignore[attr-defined]
        wall, cpu = time.perf_counter(), time.process_time()
        record = episode.run_episode(EpisodeSpec(task=task, seed=seed, planner=planner, llm="llamacpp:smollm2"))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        requests, reasons = rejected_reasons(cache)
    names = [r for r in reasons if any(p in r for p in NAME_REASONS)]
    n = max(1, record.high_level_steps)
    return {
        "planner": planner, "enums": enums, "task": task, "seed": seed, "steps": record.high_level_steps,
        "error": record.error, "wall_s_per_step": round(wall / n, 1), "cpu_s_per_step": round(cpu / n, 1),
        "llm_calls": record.llm_usage.calls, "requests": requests, "rejected": len(reasons),
        "rejected_for_names": len(names), "invalid_steps": sum(a.name == "invalid" for a in record.actions),
        "reasons": [r[:120] for r in reasons][:6],
        "full_episode_cpu_min": round(cpu / n * MAX_HIGH_LEVEL_STEPS / 60, 1),
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--task", default="bringing_water")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--planners", default="more,moma-llm,bumble")
    parser.add_argument("--enums", default="auto,off")
    parser.add_argument("--steps", type=int, default=2)
    args = parser.parse_args(argv)
    for enums in args.enums.split(","):
        for planner in args.planners.split(","):
            print(json.dumps(run(args.task, planner, enums, args.steps, args.seed)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
