"""BUMBLE's VLM traffic and its cost outside the VLM, per step: one JSON line per (scene, planner).

For each scene a paper task that suits it is instantiated and ``bumble`` / ``bumble-filter`` run
``--steps`` high-level steps driven by an in-process scripted VLM (no network): the step decision
alternates between exploring and going to an object, frames and marks are picked in turn, the
filter keeps the objects of the task's categories (an ideal filter's answer), explorations are
judged not achieved. Doors are opened at the start (the scripted VLM never opens them), so the
explored part and the frame buffer grow.

Per step: VLM calls, images and image bytes sent, OpenAI's image tokens for them, buffer size, and
the time outside the VLM: ``outside_vlm_s`` = the sense and plan phases (scene-graph build, object
descriptions, filter prompt, frame selection, set-of-mark annotation, PNG encoding) plus the
buffer upkeep during the act phase (frames offered to the memory and kept: PNG encoding and
compression); ``act_s`` is the whole act phase (motion, rendering, fusing frames, upkeep).

    python benchmarks/vlm_requests.py [--scenes grocery_store_convenience house_single_floor] [--steps 20]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from collections.abc import Sequence
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from prompt_tokens import ScriptedLLM, pick_task  # noqa: E402  (benchmarks/ is on the path when run as a script)

from more_agent.eval.episode import reset_planner  # noqa: E402
from more_agent.llm.completion import ChatMessage, Completion, TokenUsage  # noqa: E402
from more_agent.llm.images import image_stats  # noqa: E402
from more_agent.planners.bumble import BUMBLE_CONFIGS, BumblePlanner  # noqa: E402
from more_agent.planners.visual_memory import VisualMemory  # noqa: E402
from more_agent.sim.goals import GoalChecker  # noqa: E402
from more_agent.sim.instantiate import instantiate  # noqa: E402

DEFAULT_SCENES = ("grocery_store_convenience", "house_single_floor")
SKILLS = ("explore", "navigate", "explore", "go_to_and_open")


def _text(messages: Sequence[ChatMessage]) -> str:
    content = messages[-1]["content"]
    return content if isinstance(content, str) else "\n".join(p["text"] for p in content if p["type"] == "text")


class ScriptedVLM(ScriptedLLM):
    """An in-process LLMClient answering the BUMBLE questions by rule (module docstring)."""

    def complete(self, messages: Sequence[ChatMessage], *, schema: Any = None, purpose: str = "", attempt: int = 0) -> Completion:
        text = _text(messages)
        if purpose == "plan":
            self.turn += 1
            answer: dict[str, Any] = {"reasoning": "", "subtask": "scripted", "skill": SKILLS[self.turn % len(SKILLS)]}
        elif purpose == "filter":
            scene = text.split("Scene:\n", 1)[1].split("\n\n", 1)[0]
            room, _, body = scene.partition(": ")
            names = [e.split(" [")[0] for e in body.split(", ")]
            answer = {"rooms": [{"room": room, "objects": [n for n in names if n.rsplit(" ", 1)[0] in self.categories]}]}
        elif purpose == "verify":
            answer = {"reasoning": "", "achieved": False}
        else:
            key = "mark" if purpose == "object" else "frame"
            offered = sum(1 for line in text.splitlines() if line.split(":")[0].removeprefix("Frame ").isdigit())
            answer = {"reasoning": "", key: 1 + self.turn % max(1, offered)}
        reply = json.dumps(answer)
        stats = image_stats(messages)
        return Completion(text=reply, parsed=answer, model="scripted", usage=TokenUsage(stats.image_tokens, 10),
                          cost_usd=0.0, cost_known=True, cached=False, latency_s=0.0, attempts=1, purpose=purpose,
                          images=stats.images, image_bytes=stats.image_bytes, image_tokens=stats.image_tokens)


class TimedMemory(VisualMemory):
    """The frame buffer, timing its upkeep."""

    seconds = 0.0

    def offer(self, frame: Any) -> Any:
        t = time.perf_counter()
        try:
            return super().offer(frame)
        finally:
            self.seconds += time.perf_counter() - t


def run(scene: str, planner_name: str, steps: int, seed: int) -> dict[str, object]:
    """``steps`` steps of one planner in one scene; per-step figures, summarised."""
    task = pick_task(scene)
    if task is None:
        return {"scene": scene, "error": "no paper task suits this scene"}
    instance = instantiate(task, scene, seed)
    for door in instance.world.scene.doors:
        instance.world.set_open(door.id, True)
    categories = {instance.world.get(n).category for n in instance.scope.values() if n in instance.world.objects}
    vlm = ScriptedVLM(categories)
    planner = BumblePlanner(BUMBLE_CONFIGS[planner_name], vlm, "scripted")
    reset_planner(planner, instance, GoalChecker(instance))
    memory = TimedMemory(planner.config.memory)
    memory.frames, planner.memory = planner.memory.frames, memory
    rows = []
    for _ in range(steps):
        before = planner.llm_usage().model_dump()
        t0 = time.perf_counter()
        planner.observe()
        action = planner.decide()
        t1 = time.perf_counter()
        upkeep = memory.seconds
        planner.execute(action)
        t2 = time.perf_counter()
        after = planner.llm_usage().model_dump()
        rows.append({
            "vlm_calls": after["calls"] - before["calls"],
            "images": after["images"] - before["images"],
            "image_kb": (after["image_bytes"] - before["image_bytes"]) / 1024,
            "image_tokens": after["image_tokens"] - before["image_tokens"],
            "buffer_frames": len(memory.frames),
            "outside_vlm_s": (t1 - t0) + (memory.seconds - upkeep),
            "act_s": t2 - t1,
        })
        if action.is_done:
            break
    summary: dict[str, object] = {"scene": scene, "planner": planner_name, "task": task, "seed": seed, "steps": len(rows),
                                  "objects_seen": len(planner.graph.objects) if planner.graph else 0}
    for key in rows[0]:
        values = [float(r[key]) for r in rows]
        summary[key] = {"median": round(statistics.median(values), 4), "max": round(max(values), 4)}
    return summary


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--scenes", nargs="+", default=list(DEFAULT_SCENES))
    parser.add_argument("--planners", nargs="+", default=list(BUMBLE_CONFIGS))
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    for scene in args.scenes:
        for name in args.planners:
            print(json.dumps(run(scene, name, args.steps, args.seed)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
