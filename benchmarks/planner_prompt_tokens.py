"""Prompt tokens per step of every LLM planner in one scene, for any checkout (before / after a change).

Each planner runs one episode through ``more-agent run`` of the checkout ``--source`` (its code on
PYTHONPATH) against the scripted stub of ``benchmarks/table_i_stub.py`` (explore, then done after
``--steps`` plans). Every request the stub received is then counted exactly with SmolLM2-135M-Instruct's
tokenizer and chat template (the ``local`` extra; the text of each message, images left out and
counted apart), so two checkouts are compared on the same counter. One JSON line per planner: steps,
requests, prompt tokens per step (all requests of the episode over its steps), the planning prompt's
tokens (median and largest over its plan requests) and images per step.

    python benchmarks/planner_prompt_tokens.py --source /path/to/checkout [--scene grocery_store_cafe] [--steps 10]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from benchmarks.table_i_stub import PLANNERS, StubBrain
from more_agent.llm.completion import ChatMessage
from more_agent.llm.llamacpp_backend import LlamaCppBackend
from more_agent.llm.local_models import bundled_model_path
from more_agent.sim.tasks import suitable_scenes, task_set
from tests.fakes.openai_server import FakeOpenAIServer
from tests.planners.vlm_brain import kind

TOKENIZER = LlamaCppBackend(bundled_model_path("smollm2"))


def text_messages(body: dict[str, Any]) -> tuple[list[ChatMessage], int]:
    """A request's messages with text content only, and how many images they carried."""
    out, images = [], 0
    for m in body["messages"]:
        content = m["content"]
        if not isinstance(content, str):
            images += sum(p["type"] == "image_url" for p in content)
            content = "\n".join(p["text"] for p in content if p["type"] == "text")
        out.append(ChatMessage(role=m["role"], content=content))
    return out, images


def is_plan(body: dict[str, Any]) -> bool:
    """Whether a request is a step decision (MORE / MoMa-LLM's plan, BUMBLE's subtask and skill)."""
    system = body["messages"][0]["content"]
    return kind(body) == "plan" and "label the rooms" not in system


def run_planner(source: Path, planner: str, task: str, scene: str, steps: int) -> dict[str, Any]:
    """One episode of ``planner`` run by the checkout ``source``; its requests' token counts."""
    brain = StubBrain(steps)
    with FakeOpenAIServer(responder=brain) as server, tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "PYTHONPATH": str(source), "OPENAI_BASE_URL": server.base_url, "OPENAI_API_KEY": "sk-stub",
               "MORE_AGENT_LLM_CONFIG": "", "MORE_AGENT_LLM_CACHE_MODE": "off"}
        command = ["more-agent", "run", task, "--scene", scene, "--seed", "0",
                   "--planner", planner, "--llm", "openai:stub", "--out", out]
        done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=source, check=False)
        record = json.loads((Path(out) / "episode.json").read_text()) if (Path(out) / "episode.json").exists() else {}
        bodies = [r.body for r in server.requests]
    counted = [(TOKENIZER.prompt_tokens(text_messages(b)[0]), text_messages(b)[1], is_plan(b)) for b in bodies]
    plans = [t for t, _, plan in counted if plan]
    n = max(1, int(record.get("high_level_steps", 0)))
    return {
        "planner": planner, "task": task, "scene": scene, "exit": done.returncode, "error": record.get("error"),
        "steps": record.get("high_level_steps"), "requests": len(bodies),
        "prompt_tokens_per_step": round(sum(t for t, _, _ in counted) / n),
        "plan_prompt_tokens_median": round(statistics.median(plans)) if plans else None,
        "plan_prompt_tokens_max": max(plans) if plans else None,
        "images_per_step": round(sum(i for _, i, _ in counted) / n, 1),
        "invalid_steps": sum(a["name"] == "invalid" for a in record.get("actions", [])),
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--source", type=Path, default=Path.cwd(), help="checkout whose more_agent runs the episodes")
    parser.add_argument("--scene", default="grocery_store_cafe")
    parser.add_argument("--task", help="default: the first paper task that suits the scene")
    parser.add_argument("--planners", default=",".join(PLANNERS))
    parser.add_argument("--steps", type=int, default=10)
    args = parser.parse_args(argv)
    task = args.task or next(t for t in task_set("more-paper") if args.scene in suitable_scenes(t))
    for planner in args.planners.split(","):
        print(json.dumps(run_planner(args.source.resolve(), planner, task, args.scene, args.steps)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
