"""A local model driving the MORE planner on this machine: tokens per second, seconds per step, valid answers.

For each task, its first suitable scene is instantiated and the ``more`` planner runs up to ``--steps``
high-level steps with a local GGUF model in this process (``--llm``, default the bundled
SmolLM2-135M-Instruct; response cache off, so every answer is generated). Every LLM call is recorded:

- prompt and generation speed from llama.cpp's own counters (prompt tokens it actually evaluated, as
  llama-cpp-python reuses the cached prefix of the previous prompt, and tokens it generated);
- whether the answer parses against the schema it was asked for (grammar-constrained decoding
  should make this 100 %), and whether the first ask of each question was accepted by the
  validator (a known skill, room and object) without a re-ask.

One JSON line per task and a summary line; ``s_per_step`` is one high-level step's wall time (sense,
room labels, filter, plan, act), ``cpu_s_per_step`` the CPU time this process used in it (less
affected by other load on the machine; ``load_avg`` is the 1-minute load at the start and the end),
``llm_share`` the part of the wall time spent in the model. ``threads`` are llama.cpp's threads for
generation and for prompts (its default: half the cores and all of them).

    python benchmarks/local_llm.py [--llm llamacpp:smollm2] [--tasks putting_shopping_away ...] [--steps 3] [--threads N]
        [--planner more|moma-llm|moma-llm-sr] [--name-enums auto|on|off]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ValidationError

from more_agent.eval.episode import reset_planner
from more_agent.llm import CacheMode, ChatClient, ChatMessage, Completion, Unparseable, load_llm_config, make_client
from more_agent.llm.llamacpp_backend import LlamaCppBackend
from more_agent.llm.reask import REASK_TEMPLATE
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner
from more_agent.sim.goals import GoalChecker
from more_agent.sim.instantiate import instantiate
from more_agent.sim.tasks import suitable_scenes

DEFAULT_TASKS = ("putting_shopping_away", "clearing_the_table_after_dinner")
_REASK_PREFIX = REASK_TEMPLATE.split("{", 1)[0]


@dataclass(frozen=True)
class Call:
    """One LLM call as the benchmark saw it."""

    purpose: str
    reask: bool
    """The question was asked again after an unusable answer."""
    schema_valid: bool
    prompt_tokens_evaluated: int
    prompt_ms: float
    generated_tokens: int
    generation_ms: float


class MeasuredClient:
    """An LLMClient over a llama.cpp ChatClient that records a :class:`Call` per request."""

    def __init__(self, client: ChatClient) -> None:
        if not isinstance(client.backend, LlamaCppBackend):
            raise SystemExit(f"--llm must name a llamacpp model, not {client.backend.kind}")
        self.client, self.backend = client, client.backend
        self.name_enums = client.name_enums
        """Forwarded: the planners enumerate valid names in their schemas when the client asks for it."""
        self.calls: list[Call] = []

    @property
    def model(self) -> str:
        return self.client.model

    def _perf(self) -> Any:
        import llama_cpp

        return llama_cpp.llama_perf_context(self.backend.llama().ctx)

    def complete(self, messages: Sequence[ChatMessage], *, schema: type[BaseModel] | None = None, purpose: str = "",
                 attempt: int = 0) -> Completion:
        before = self._perf()
        try:
            completion = self.client.complete(messages, schema=schema, purpose=purpose, attempt=attempt)
        except Unparseable as e:
            self._record(messages, schema, purpose, e.completion, before)
            raise
        self._record(messages, schema, purpose, completion, before)
        return completion

    def _record(self, messages: Sequence[ChatMessage], schema: type[BaseModel] | None, purpose: str,
                completion: Completion, before: Any) -> None:
        after = self._perf()
        self.calls.append(Call(
            purpose=purpose, reask=messages[-1]["content"].startswith(_REASK_PREFIX),
            schema_valid=schema is None or _parses(schema, completion.text),
            prompt_tokens_evaluated=after.n_p_eval - before.n_p_eval, prompt_ms=after.t_p_eval_ms - before.t_p_eval_ms,
            generated_tokens=after.n_eval - before.n_eval, generation_ms=after.t_eval_ms - before.t_eval_ms,
        ))


def _parses(schema: type[BaseModel], text: str) -> bool:
    try:
        schema.model_validate_json(text)
    except ValidationError:
        return False
    return True


def first_try_share(calls: Sequence[Call]) -> float:
    """Share of questions whose first answer was accepted: a first ask not followed by a re-ask."""
    firsts = [i for i, c in enumerate(calls) if not c.reask]
    accepted = [i for i in firsts if i + 1 == len(calls) or not calls[i + 1].reask]
    return len(accepted) / len(firsts) if firsts else float("nan")


def summary(calls: Sequence[Call]) -> dict[str, object]:
    """Speeds and shares over ``calls``."""
    prompt_ms, gen_ms = sum(c.prompt_ms for c in calls), sum(c.generation_ms for c in calls)
    return {
        "calls": len(calls),
        "prompt_tokens_per_s": round(1000 * sum(c.prompt_tokens_evaluated for c in calls) / prompt_ms, 1) if prompt_ms else None,
        "generation_tokens_per_s": round(1000 * sum(c.generated_tokens for c in calls) / gen_ms, 1) if gen_ms else None,
        "schema_valid_share": round(sum(c.schema_valid for c in calls) / len(calls), 4) if calls else None,
        "valid_first_try_share": round(first_try_share(calls), 4),
        "reasks": sum(c.reask for c in calls),
    }


def run_task(task: str, client: MeasuredClient, steps: int, seed: int, planner_name: str = "more") -> dict[str, object]:
    """Up to ``steps`` high-level steps of ``planner_name`` on the task's first suitable scene."""
    scene = suitable_scenes(task)[0]
    instance = instantiate(task, scene, seed)
    planner = LLMPlanner(PLANNER_CONFIGS[planner_name], LLMClients(client, client, f"llamacpp:{client.model}"))
    first_call = len(client.calls)
    reset_planner(planner, instance, GoalChecker(instance))
    step_s, cpu_s, llm_s = [], [], []
    for _ in range(steps):
        t0, c0, waited = time.perf_counter(), time.process_time(), planner.llm_usage().seconds
        planner.observe()
        action = planner.decide()
        planner.execute(action)
        step_s.append(time.perf_counter() - t0)
        cpu_s.append(time.process_time() - c0)
        llm_s.append(planner.llm_usage().seconds - waited)
        if action.is_done:
            break
    calls = client.calls[first_call:]
    by_purpose = {p: summary([c for c in calls if c.purpose == p]) for p in sorted({c.purpose for c in calls})}
    return {
        "task": task, "scene": scene, "seed": seed, "steps": len(step_s),
        "actions": [f"{a.name}({', '.join(a.arguments)}){'' if a.ok else ' failed'}" for a in planner.history],
        "s_per_step": {"median": round(statistics.median(step_s), 2), "max": round(max(step_s), 2)},
        "cpu_s_per_step": {"median": round(statistics.median(cpu_s), 2), "max": round(max(cpu_s), 2)},
        "llm_share": round(sum(llm_s) / sum(step_s), 3),
        **summary(calls), "by_purpose": by_purpose,
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--llm", default="llamacpp:smollm2", help="a llamacpp: spec (GGUF path or bundled name)")
    parser.add_argument("--tasks", nargs="+", default=list(DEFAULT_TASKS))
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=None, help="llama.cpp threads (default: llama.cpp's choice)")
    parser.add_argument("--planner", default="more", choices=sorted(PLANNER_CONFIGS))
    parser.add_argument("--name-enums", default="auto", choices=["auto", "on", "off"],
                        help="enumerate valid names in the answer schemas (auto: on for llama.cpp)")
    args = parser.parse_args(argv)
    load_start = round(os.getloadavg()[0], 1)
    config = load_llm_config(overrides={"cache_mode": CacheMode.OFF, "llamacpp_n_threads": args.threads,
                                        "name_enums": args.name_enums})
    client = MeasuredClient(make_client(args.llm, config))
    t0 = time.perf_counter()
    client.backend.llama()
    load_s = time.perf_counter() - t0
    rows = []
    for task in args.tasks:
        rows.append(run_task(task, client, args.steps, args.seed, args.planner))
        print(json.dumps(rows[-1]), flush=True)
    steps = [r["s_per_step"]["median"] for r in rows]  # type: ignore[index]
    print(json.dumps({
        "summary": True, "llm": args.llm, "model": client.model, "planner": args.planner,
        "name_enums": client.name_enums, "n_ctx": client.backend.n_ctx,
        "threads": [client.backend.llama().n_threads, client.backend.llama().n_threads_batch], "cpus": os.cpu_count(),
        "load_avg": [load_start, round(os.getloadavg()[0], 1)], "load_s": round(load_s, 2),
        "s_per_step_median_of_tasks": round(statistics.median(steps), 2), **summary(client.calls),
    }), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
