"""BUMBLE's long- and short-term memory: the failure store across trials, the messages of earlier steps."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from more_agent.errors import UserError
from more_agent.eval.episode_folder import read_record
from more_agent.eval.harness import DEFAULT_EPISODE_FN, evaluate
from more_agent.eval.store import RunConfig, read_records
from more_agent.llm.images import png_bytes
from more_agent.planners.bumble_memory import (
    LONG_TERM_INTRO,
    SHORT_TERM_INTRO,
    FailureStore,
    PastStep,
    downscaled_png,
    long_term_message,
    short_term_messages,
)
from more_agent.skills import INVALID
from tests.planners.brain import BrainServer
from tests.planners.test_bumble import Short
from tests.planners.test_llm_episode import KITCHEN, TASK
from tests.planners.vlm_brain import kind


def _png(side: int) -> bytes:
    return png_bytes(np.zeros((side, side, 3), dtype=np.uint8))


def test_short_term_messages_bound_the_images_and_keep_every_step() -> None:
    steps = [PastStep(f"grasp apple {k}", "go_to_and_grasp", k % 2 == 0, "too far", _png(8)) for k in range(11)]
    messages = short_term_messages(steps, max_images=3)
    users = [m for m in messages[1:] if m["role"] == "user"]
    assert len(users) == 11 and [len(m["content"]) for m in users] == [1] * 8 + [2] * 3
    assert "Step 2 - subtask: grasp apple 1; skill: go_to_and_grasp; success: no; feedback: too far" in users[1]["content"][0]["text"]
    assert short_term_messages([]) == []
    small = Image.open(io.BytesIO(downscaled_png(_png(256))))
    assert small.size == (128, 128)


def test_failure_store_keeps_summaries_per_task_and_rejects_a_broken_file(tmp_path: Path) -> None:
    store = FailureStore(tmp_path / "mem" / "bumble.jsonl")
    assert store.summaries("putting_shopping_away") == []
    store.add("putting_shopping_away", ["choosing explore failed: nothing new"])
    store.add("other_task", ["x"])
    store.add("putting_shopping_away", ["choosing go_to_and_grasp failed: hand full"])
    store.add("putting_shopping_away", [])
    assert store.summaries("putting_shopping_away") == [
        "choosing explore failed: nothing new",
        "choosing go_to_and_grasp failed: hand full",
    ]
    message = long_term_message(store.summaries("putting_shopping_away"), limit=1)[0]["content"]
    assert message.startswith(LONG_TERM_INTRO) and "hand full" in message and "nothing new" not in message
    with store.path.open("a") as f:
        f.write("not json\n")
    with pytest.raises(UserError, match=r"bumble.jsonl:4: not a long-term memory entry"):
        store.summaries("putting_shopping_away")
    assert len(store.path.read_text().splitlines()) == 4  # nothing written was lost


class ShortTrials:
    """A fresh ``Short`` brain for every episode (one whose first step decision carries no earlier steps):
    the first one answers its landmark question wrongly until the step is invalid."""

    def __init__(self) -> None:
        self.brains = [Short("landmark", bad=3), Short(), Short()]
        self.episode = -1

    def __call__(self, body: dict[str, Any]) -> str:
        if kind(body) == "plan" and SHORT_TERM_INTRO not in json.dumps(body["messages"]):
            self.episode += 1
        return self.brains[self.episode](body)


def test_failures_of_one_trial_reach_the_next_trial(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """BUMBLE's --add_past through `eval --trials 2 --long-term-memory`: the failed step of trial 0 is a summary
    in its record and in every step prompt of trial 1, and never in trial 0's own prompts."""
    brain = ShortTrials()
    with BrainServer(brain) as server:
        for name, value in {
            "OPENAI_BASE_URL": server.base_url,
            "OPENAI_API_KEY": "sk-test",
            "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite"),
            "MORE_AGENT_LLM_CONFIG": "",
        }.items():
            monkeypatch.setenv(name, value)
        config = RunConfig(
            planner="bumble",
            llm="openai:fake-model",
            tasks=[TASK],
            scene=str(KITCHEN),
            seeds=[0],
            trials=2,
            long_term_memory=True,
            episode_fn=DEFAULT_EPISODE_FN,
        )
        records = evaluate(config, tmp_path / "run", show_progress=False)
    assert brain.episode == 1
    first, second = sorted(records, key=lambda r: r.trial)
    assert (first.trial, second.trial) == (0, 1) and first.long_term_memory and second.long_term_memory
    assert first.error is None and second.error is None
    assert any(a.name == INVALID for a in first.actions)
    summary = next(s for s in first.failure_summaries if "invalid answer" in s)
    assert read_records(tmp_path / "run") == records  # the records are the memory: stored as run
    plans = [json.dumps(r.body["messages"]) for r in server.requests if kind(r.body) == "plan"]
    trial_0 = [p for p in plans if LONG_TERM_INTRO not in p]
    trial_1 = [p for p in plans if LONG_TERM_INTRO in p]
    assert len(trial_0) == len(trial_1) == 3  # Short ends each episode at its third step decision
    assert all(json.dumps(summary)[1:-1] in p for p in trial_1)


def test_run_carries_failures_across_invocations_in_its_memory_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`more-agent run --bumble-memory FILE`: each run is a trial; the file gets the failures after the episode."""
    from typer.testing import CliRunner

    from more_agent.cli import app

    memory = tmp_path / "memory.jsonl"
    brain = ShortTrials()
    run = ["run", TASK, "--scene", str(KITCHEN), "--planner", "bumble", "--llm", "openai:fake-model",
           "--bumble-memory", str(memory)]
    with BrainServer(brain) as server:
        for name, value in {"OPENAI_BASE_URL": server.base_url, "OPENAI_API_KEY": "sk-test",
                            "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite"), "MORE_AGENT_LLM_CONFIG": ""}.items():
            monkeypatch.setenv(name, value)
        for k in range(2):
            result = CliRunner().invoke(app, [*run, "--out", str(tmp_path / f"trial{k}")])
            assert result.exit_code == 0, result.output
    first, second = (read_record(tmp_path / f"trial{k}" / "episode.json") for k in range(2))
    stored = [json.loads(line) for line in memory.read_text().splitlines()]
    assert [e["summary"] for e in stored] == first.failure_summaries + second.failure_summaries
    assert first.failure_summaries and all(e["task"] == TASK for e in stored)
    assert first.long_term_memory and second.long_term_memory
    plans = [json.dumps(r.body["messages"]) for r in server.requests if kind(r.body) == "plan"]
    assert not any(LONG_TERM_INTRO in p for p in plans[:3]) and all(LONG_TERM_INTRO in p for p in plans[3:])
