"""Prompt size with and without scene filtering, LLM calls and planning overhead per step: one JSON per scene.

For each scene, a paper task that suits it is instantiated and the MORE planner runs ``--steps``
high-level steps driven by an in-process scripted LLM (no network): rooms are labelled by a keyword
rule, the filter keeps the objects of the task's categories and the rooms that hold one or have
unexplored areas (an ideal answer to the filter prompt, which asks to keep exactly those), and the
plan explores the rooms with unexplored areas in turn. On every recorded state the planning prompt
is rendered twice, once with the full scene text (no filtering, as MoMa-LLM) and once with the
filtered text (MORE), so both sizes come from the same states. Unless ``--keep-doors`` is given,
every door is opened at the start: the scripted explorer never opens doors, and the point is to
see the prompt grow as the explored part of a large scene does.

Tokens are counted exactly by SmolLM2-135M-Instruct's tokenizer and chat template (llama.cpp) when
the ``local`` extra is installed; otherwise they are estimated as one token per word or punctuation
mark, a rough stand-in for tiktoken's counts. Each line's ``token_counts`` says which. The scene
text alone is reported too, as the prompt's fixed part (instructions, skill API) does not change
with filtering.
``overhead_s`` is the time of one step's sense + plan phases outside the LLM (graph build, room
labels, language, filtering, parsing) on one core; ``act_s`` is the subpolicy's time (motion,
rendering and fusing frames).

``--task`` runs that task in every scene instead (for scenes no paper task suits, e.g. most offices).

    python benchmarks/prompt_tokens.py [--scenes house_single_floor Beechwood_0_garden ...] [--steps 30] [--keep-doors]
        [--task T]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import sys
import time
from collections.abc import Sequence
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from more_agent.errors import UserError  # noqa: E402
from more_agent.eval.episode import reset_planner  # noqa: E402
from more_agent.llm import plan_messages  # noqa: E402
from more_agent.llm.completion import ChatMessage, Completion, TokenUsage  # noqa: E402
from more_agent.llm.errors import LLMConfigError  # noqa: E402
from more_agent.llm.llamacpp_backend import LlamaCppBackend  # noqa: E402
from more_agent.llm.local_models import bundled_model_path  # noqa: E402
from more_agent.planners.llm_planner import PLANNER_CONFIGS, LLMClients, LLMPlanner  # noqa: E402
from more_agent.sim.goals import GoalChecker  # noqa: E402
from more_agent.sim.instantiate import instantiate  # noqa: E402
from more_agent.sim.tasks import suitable_scenes, task_set  # noqa: E402

DEFAULT_SCENES = ("house_single_floor", "house_double_floor_lower", "Beechwood_0_garden", "Wainscott_0_garden")
"""Large scenes (several rooms, gardens) where filtering matters."""

_TOKEN = re.compile(r"\w+|[^\w\s]")
_ENTRY = re.compile(r"([A-Za-z_]+(?: [A-Z]+)?)(?: \(x\d+\))?(?: \[([^\]]*)\])?")
_ROOM_WORDS = {"kitchen": ("fridge", "oven", "stove", "dishwasher"), "bedroom": ("bed",), "bathroom": ("toilet", "bathtub")}


def _tokenizer() -> LlamaCppBackend | None:
    """The bundled SmolLM2 model when the ``local`` extra is installed (exact counts), else None (estimates)."""
    try:
        return LlamaCppBackend(bundled_model_path("smollm2"))
    except LLMConfigError:
        return None


TOKENIZER = _tokenizer()
TOKEN_COUNTS = ("exact: SmolLM2-135M-Instruct tokenizer and chat template (llama.cpp)" if TOKENIZER is not None
                else "estimate: one per word or punctuation mark, 4 per message (no tokenizer installed)")


def tokens(text: str) -> int:
    """Tokens of a text: exact with the tokenizer, else estimated (see module docstring)."""
    if TOKENIZER is not None:
        return len(TOKENIZER.llama().tokenize(text.encode("utf-8"), add_bos=False))
    return len(_TOKEN.findall(text))


def prompt_tokens(messages: Sequence[ChatMessage]) -> int:
    """Tokens of a chat prompt: exact (chat template applied) with the tokenizer, else contents plus 4 per message."""
    if TOKENIZER is not None:
        return TOKENIZER.prompt_tokens(messages)
    return sum(tokens(m["content"]) + 4 for m in messages)


def _scene_lines(user: str) -> str:
    return user.split("Scene:\n", 1)[1].split("\n\n", 1)[0]


def _unexplored_rooms(user: str) -> list[str]:
    """Rooms marked as having unexplored areas in the scene lines of a prompt."""
    return re.findall(r"^(\S+) \(unexplored areas\)", _scene_lines(user), flags=re.M)


def _scene_entries(user: str) -> dict[str, list[tuple[str, str]]]:
    """Room -> (object name, attributes) from the scene lines of a prompt."""
    scene = _scene_lines(user)
    rooms: dict[str, list[tuple[str, str]]] = {}
    for line in scene.splitlines():
        head, _, body = line.partition(": ")
        rooms[head.replace(" (unexplored areas)", "")] = [
            (m.group(1), m.group(2) or "") for m in _ENTRY.finditer(body) if body != "no objects seen" and m.group(1)
        ]
    return rooms


class ScriptedLLM:
    """An in-process :class:`~more_agent.llm.LLMClient` answering room, filter and plan prompts by rule."""

    def __init__(self, categories: set[str]) -> None:
        self.categories = categories
        self.turn = 0

    @property
    def model(self) -> str:
        return "scripted"

    def complete(self, messages: Sequence[ChatMessage], *, schema: Any = None, purpose: str = "", attempt: int = 0) -> Completion:
        user = messages[-1]["content"]
        if purpose == "room":
            words = user.split("Possible room types")[0]
            room = next((r for r, keys in _ROOM_WORDS.items() if any(k in words for k in keys)), "living_room")
            answer: dict[str, Any] = {"room": room}
        elif purpose == "filter":
            unexplored = set(_unexplored_rooms(user))
            kept = {r: [n for n, _ in objs if n.rsplit(" ", 1)[0] in self.categories]
                    for r, objs in _scene_entries(user).items()}
            answer = {"rooms": [{"room": r, "objects": objs} for r, objs in kept.items()
                                if r in unexplored or set(objs) - {"floor"}]}
        else:
            unexplored = _unexplored_rooms(user)
            self.turn += 1
            answer = ({"reasoning": "", "skill": "explore", "arguments": [unexplored[self.turn % len(unexplored)]]}
                      if unexplored else {"reasoning": "", "skill": "done", "arguments": []})
        text = json.dumps(answer)
        return Completion(text=text, parsed=answer, model="scripted",
                          usage=TokenUsage(prompt_tokens(messages), tokens(text)), cost_usd=0.0, cost_known=True,
                          cached=False, latency_s=0.0, attempts=1, purpose=purpose)


def pick_task(scene: str) -> str | None:
    """The first paper task that suits ``scene``."""
    return next((t for t in task_set("more-paper") if scene in suitable_scenes(t)), None)


def run_scene(scene: str, steps: int, seed: int, open_doors: bool = True, task: str | None = None) -> dict[str, object]:
    """Record ``steps`` planning steps in one scene (with ``task``, else the first paper task that
    suits it); sizes and times per step, summarised."""
    task = task or pick_task(scene)
    if task is None:
        return {"scene": scene, "error": "no paper task suits this scene (pass --task)"}
    instance = instantiate(task, scene, seed)
    if open_doors:
        for door in instance.world.scene.doors:
            instance.world.set_open(door.id, True)
    categories = {instance.world.get(n).category for n in instance.scope.values() if n in instance.world.objects}
    llm = ScriptedLLM(categories)
    planner = LLMPlanner(PLANNER_CONFIGS["more"], LLMClients(llm, llm, "scripted"))
    reset_planner(planner, instance, GoalChecker(instance))
    rows = []
    for _ in range(steps):
        calls_before = planner.llm_usage().calls
        t0 = time.perf_counter()
        planner.observe()
        action = planner.decide()
        t1 = time.perf_counter()
        view, planning = planner.view, planner.planning_view
        assert view is not None and planning is not None
        scene_text, planning_text = view.text(), planning.text()
        plan_kw = dict(task=planner.task, robot_room=view.robot_room, held_object=view.held, history=planner.history,
                       feedback=planner.feedback)
        rows.append({
            "plan_tokens_unfiltered": prompt_tokens(plan_messages(scene=scene_text, **plan_kw)),
            "plan_tokens_filtered": prompt_tokens(plan_messages(scene=planning_text, **plan_kw)),
            "scene_tokens_unfiltered": tokens(scene_text),
            "scene_tokens_filtered": tokens(planning_text),
            "llm_calls": planner.llm_usage().calls - calls_before,
            "overhead_s": t1 - t0,
        })
        t2 = time.perf_counter()
        planner.execute(action)
        rows[-1]["act_s"] = time.perf_counter() - t2
        if action.is_done:
            break
    summary: dict[str, object] = {"scene": scene, "task": task, "seed": seed, "steps": len(rows), "token_counts": TOKEN_COUNTS,
                                  "rooms_seen": len(planner.view.rooms) if planner.view else 0,
                                  "objects_seen": len(planner.graph.objects) if planner.graph else 0}
    for key in rows[0]:
        values = [float(r[key]) for r in rows]
        summary[key] = {"median": round(statistics.median(values), 4), "max": round(max(values), 4)}
    full = sum(r["plan_tokens_unfiltered"] for r in rows)
    summary["plan_token_reduction"] = round(1 - sum(r["plan_tokens_filtered"] for r in rows) / full, 4)
    summary["per_step"] = rows
    return summary


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--scenes", nargs="+", default=list(DEFAULT_SCENES))
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--keep-doors", action="store_true", help="leave doors as generated (some closed)")
    parser.add_argument("--task", help="run this task in every scene (default: the first paper task that suits it)")
    args = parser.parse_args(argv)
    for scene in args.scenes:
        try:
            line = run_scene(scene, args.steps, args.seed, open_doors=not args.keep_doors, task=args.task)
        except UserError as e:  # an unknown task or scene, a task the scene does not suit
            print(f"error: {e}", file=sys.stderr)
            return 2
        print(json.dumps(line), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
