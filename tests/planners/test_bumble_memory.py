"""BUMBLE's long- and short-term memory: the failure store across trials, the messages of earlier steps."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from more_agent.errors import UserError
from more_agent.llm.images import png_bytes
from more_agent.planners.bumble_memory import (
    ENV_MEMORY,
    LONG_TERM_INTRO,
    FailureStore,
    PastStep,
    downscaled_png,
    long_term_message,
    short_term_messages,
)
from more_agent.skills import INVALID
from tests.fakes.openai_server import request_text
from tests.planners.brain import BrainServer
from tests.planners.test_bumble import Short, _run
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
    assert store.summaries("put the apple away") == []
    store.add("put the apple away", "choosing explore failed: nothing new")
    store.add("other task", "x")
    store.add("put the apple away", "choosing go_to_and_grasp failed: hand full")
    assert store.summaries("put the apple away") == ["choosing explore failed: nothing new",
                                                     "choosing go_to_and_grasp failed: hand full"]
    message = long_term_message(store.summaries("put the apple away"), limit=1)[0]["content"]
    assert message.startswith(LONG_TERM_INTRO) and "hand full" in message and "nothing new" not in message
    with store.path.open("a") as f:
        f.write("not json\n")
    with pytest.raises(UserError, match=r"bumble.jsonl:4: not a long-term memory entry"):
        store.summaries("put the apple away")
    assert len(store.path.read_text().splitlines()) == 4  # nothing written was lost


def test_failures_of_one_trial_reach_the_next_trial(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """BUMBLE's --add_past: a failed step of trial 1 is a summary in every step prompt of trial 2."""
    memory = tmp_path / "bumble_memory.jsonl"
    monkeypatch.setenv(ENV_MEMORY, str(memory))
    with BrainServer(Short("landmark", bad=3)) as server:
        first, _ = _run(server, tmp_path / "trial1")
    assert any(a.name == INVALID for a in first.actions)
    stored = [json.loads(line) for line in memory.read_text().splitlines()]
    assert stored and all(e["task"] == first.description for e in stored)
    assert any("invalid answer" in e["summary"] for e in stored)
    with BrainServer(Short()) as server:
        _run(server, tmp_path / "trial2")
    plans = [r.body for r in server.requests if kind(r.body) == "plan"]
    assert plans and all(LONG_TERM_INTRO in json.dumps(b["messages"]) for b in plans)
    assert "invalid answer" in json.dumps(plans[0]["messages"][1]) and "Task:" in request_text(plans[0])
