"""Table I with a scripted stub LLM: every LLM planner on paper tasks, seed 0, through ``more-agent eval``.

No model is involved: the stub is the test suite's local OpenAI-compatible server
(``tests.fakes.openai_server``) answering by rule. Rooms get the first room type offered, the filter
keeps every object, a plan explores a room with unexplored areas (MORE's scene text, MoMa-LLM's
encoding) and BUMBLE explores the first frame offered and judges the subtask not achieved; after
``--steps`` plans of an episode it calls done. So the run shows that every planner goes through the
whole pipeline without errors and what each costs in LLM calls and tokens; its SR says nothing about
any model. Token counts are estimated (one per word or punctuation mark of the text, images left
out; images are counted apart by the client), since the stub has no tokenizer.

    python benchmarks/table_i_stub.py --out /tmp/table_i_stub [--tasks a,b] [--planners more,bumble] [--steps 6]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from more_agent.eval.report import llm_markdown, table_i_markdown
from more_agent.eval.store import read_records
from tests.fakes.openai_server import FakeOpenAIServer, Reply
from tests.planners.brain import MOMA_ROOMS, parse_moma_prompt, parse_prompt
from tests.planners.vlm_brain import kind, user_text

TASKS = (
    "assembling_gift_baskets",
    "bringing_newspaper_in",
    "buy_alcohol",
    "buy_food_for_a_party",
    "cleaning_up_branches_and_twigs",
    "loading_the_car",
    "packing_art_supplies_into_car",
    "preparing_lunch_box",
    "putting_leftovers_away",
    "setting_up_room_for_games",
)
"""Ten paper tasks: every fifth one of the more-paper set (its order), so stores, houses and gardens mix."""

PLANNERS = ("more", "moma-llm", "moma-llm-sr", "bumble", "bumble-filter")
"""Every LLM planner of the registry (``more-agent eval --help``)."""

_TOKEN = re.compile(r"\w+|[^\w\s]")
_TASK = re.compile(r"(?:^Task: |Your task: )(.+)$", re.M)


def estimate_tokens(text: str) -> int:
    """One token per word or punctuation mark (a rough stand-in for a tokenizer)."""
    return len(_TOKEN.findall(text))


class StubBrain:
    """Answers every request of the LLM and VLM planners by rule (module docstring)."""

    def __init__(self, steps: int) -> None:
        self.steps = steps
        self.plans: Counter[str] = Counter()
        """Plan requests seen per task text (one episode per task in a run)."""

    def __call__(self, body: dict[str, Any]) -> Reply:
        text = user_text(body)
        system = body["messages"][0]["content"]
        answer = self.answer(system if isinstance(system, str) else "", text)
        prompt = estimate_tokens(system if isinstance(system, str) else "") + estimate_tokens(text)
        return Reply(answer, prompt_tokens=prompt, completion_tokens=estimate_tokens(answer))

    def answer(self, system: str, text: str) -> str:
        if "Possible room types: " in text:
            return json.dumps({"room": text.split("Possible room types: ", 1)[1].split(",")[0].split("\n")[0].strip()})
        if "Remove every object" in system:
            rooms = parse_prompt(text).rooms
            return json.dumps({"rooms": [{"room": r, "objects": list(objs)} for r, objs in rooms.items()]})
        question = kind({"messages": [{"role": "system", "content": system}]})
        if question in ("landmark", "explore"):
            return json.dumps({"reasoning": "stub", "frame": 1})
        if question == "object":
            return json.dumps({"reasoning": "stub", "mark": 1})
        if question == "verify":
            return json.dumps({"reasoning": "stub", "achieved": False})
        return self.plan(system, text)

    def plan(self, system: str, text: str) -> str:
        task = _TASK.search(system + "\n" + text)
        key = task.group(1) if task else ""
        self.plans[key] += 1
        finished = self.plans[key] > self.steps
        if "subtask" in system:  # BUMBLE's step question
            skill = "done" if finished else "explore"
            return json.dumps({"reasoning": "stub", "subtask": "look around", "skill": skill})
        scene = parse_moma_prompt(text) if MOMA_ROOMS in text else parse_prompt(text)
        rooms = scene.unexplored
        if finished or not rooms:
            command: dict[str, Any] = {"skill": "done", "arguments": []}
        else:
            command = {"skill": "explore", "arguments": [rooms[self.plans[key] % len(rooms)]]}
        head = {"analysis": "stub", "reasoning": "stub"} if MOMA_ROOMS in text else {"reasoning": "stub"}
        return json.dumps({**head, **command})


def run_planner(planner: str, tasks: Sequence[str], out: Path, steps: int, workers: int) -> dict[str, Any]:
    """One ``more-agent eval`` of ``planner`` against a fresh stub; its exit status, wall time and output."""
    with FakeOpenAIServer(responder=StubBrain(steps)) as server:
        env = {
            **os.environ,
            "OPENAI_BASE_URL": server.base_url,
            "OPENAI_API_KEY": "sk-stub",
            "MORE_AGENT_LLM_CONFIG": "",
            "MORE_AGENT_LLM_CACHE_MODE": "off",
        }
        command = ["more-agent", "eval", "--tasks", ",".join(tasks), "--planner", planner, "--llm", "openai:stub"]
        command += ["--out", str(out / planner), "--workers", str(workers), "--no-progress"]
        start = time.perf_counter()
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    return {"planner": planner, "exit": done.returncode, "wall_s": round(time.perf_counter() - start, 1),
            "stderr_tail": done.stderr[-400:] if done.returncode else ""}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--tasks", default=",".join(TASKS))
    parser.add_argument("--planners", default=",".join(PLANNERS))
    parser.add_argument("--steps", type=int, default=6, help="plans per episode before the stub calls done")
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args(argv)
    tasks = args.tasks.split(",")
    status = 0
    for planner in args.planners.split(","):
        line = run_planner(planner, tasks, args.out, args.steps, args.workers)
        print(json.dumps(line), flush=True)
        status = status or line["exit"]
    records = [r for p in args.planners.split(",") for r in read_records(args.out / p)]
    print(table_i_markdown(records) + "\n\n" + llm_markdown(records))
    errors = [(r.planner, r.task, r.error) for r in records if r.error]
    print(f"\nepisodes: {len(records)}, errors: {len(errors)}", *errors, sep="\n")
    return status


if __name__ == "__main__":
    sys.exit(main())
