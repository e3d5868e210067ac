"""Fault injection through the real CLI, client and local OpenAI-compatible server: every fault mode
of ``tests.fakes.faults`` ends with the documented exit status and message, loses or duplicates
nothing, and the API key appears in no file the run writes nor on the terminal."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.store import read_records
from tests.fakes.faults import FAULT_KINDS, fault_items
from tests.fakes.openai_server import FakeOpenAIServer, Status

runner = CliRunner()
KEY = "sk-test-DO-NOT-LEAK-0123456789abcdef"
KITCHEN = Path(__file__).parent / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"
RUN = ["run", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", "openai:fake-model"]
EVAL = ["eval", "--tasks", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", "openai:fake-model",
        "--no-progress"]


def quick_brain(body: dict[str, Any]) -> str:
    """Labels every room a kitchen, keeps nothing in the filter, then calls done() (a short episode)."""
    if "Possible room types" in body["messages"][-1]["content"]:
        return json.dumps({"room": "kitchen"})
    if "Remove every object" in body["messages"][0]["content"]:
        return json.dumps({"rooms": []})
    return json.dumps({"reasoning": "finished", "skill": "done", "arguments": []})


@pytest.fixture
def server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[FakeOpenAIServer]:
    """The fake server, and the environment of a user pointing more-agent at it with a secret key."""
    config = tmp_path / "llm.toml"
    config.write_text("timeout_s = 1.0\nmax_retries = 2\nbackoff_initial_s = 0.01\nbackoff_max_s = 0.05\n")
    with FakeOpenAIServer(responder=quick_brain) as fake:
        for name, value in {"OPENAI_BASE_URL": fake.base_url, "OPENAI_API_KEY": KEY, "MORE_AGENT_LLM_CONFIG": str(config),
                            "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite")}.items():
            monkeypatch.setenv(name, value)
        monkeypatch.delenv("MORE_AGENT_LLM", raising=False)
        yield fake


def _key_nowhere(root: Path, *outputs: str) -> None:
    for path in root.rglob("*"):
        if path.is_file():
            assert KEY.encode() not in path.read_bytes(), f"the API key was written to {path}"
    assert all(KEY not in o for o in outputs)


EXPECTED = {  # fault -> exit status of `more-agent run`, text in the output
    "oversize": (0, "success"),
    "oversize_name": (0, "failure"),
    "garbage": (0, "failure"),
    "burst_500": (75, "LLMServerError"),
    "rate_limit": (0, "failure"),
    "reset": (0, "failure"),
    "slow": (0, "failure"),
    "injection": (0, "failure"),
    "markup": (0, "rejected response_format json_schema (Error code: 400 - bad request [/x] [bold]markup[/bold])"),
}


@pytest.mark.parametrize("kind", FAULT_KINDS)
def test_run_survives_every_fault_mode(kind: str, server: FakeOpenAIServer, tmp_path: Path) -> None:
    server.push(*fault_items(kind))
    start = time.perf_counter()
    result = runner.invoke(app, [*RUN, "--out", str(tmp_path / "ep")])
    seconds = time.perf_counter() - start
    code, text = EXPECTED[kind]
    flat = " ".join(result.output.split())
    assert result.exit_code == code, flat
    assert "Traceback" not in result.output and result.exception is None or isinstance(result.exception, SystemExit)
    assert text in flat or kind == "oversize"
    assert len(result.output) < 20_000  # nothing a server sends is dumped whole to the terminal
    record = json.loads((tmp_path / "ep" / "episode.json").read_text())
    assert record["retryable"] is (code == 75)
    assert max(len(json.dumps(r.body)) for r in server.requests) < 60_000  # no answer echoed into a prompt
    assert (tmp_path / "cache.sqlite").stat().st_size < 1_000_000
    assert seconds < 30  # a Retry-After of an hour is capped by the configured backoff
    _key_nowhere(tmp_path, result.output)


def test_oversize_answers_every_step_still_end_the_episode(server: FakeOpenAIServer, tmp_path: Path) -> None:
    huge = fault_items("oversize", oversize_chars=200_000)[0]
    server._responder = lambda body: huge  # a model that only ever answers 200 kB
    result = runner.invoke(app, [*RUN, "--out", str(tmp_path / "ep")])
    assert result.exit_code == 0, result.output
    record = json.loads((tmp_path / "ep" / "episode.json").read_text())
    assert record["high_level_steps"] == 50 and all(a["name"] == "invalid" for a in record["actions"])
    assert max(len(a["feedback"]) for a in record["actions"]) <= 600
    assert max(len(json.dumps(r.body)) for r in server.requests) < 60_000
    assert (tmp_path / "cache.sqlite").stat().st_size < 20_000_000
    _key_nowhere(tmp_path, result.output)


def test_eval_exits_75_on_a_500_burst_and_retry_errors_recovers(server: FakeOpenAIServer, tmp_path: Path) -> None:
    out = tmp_path / "run"
    server.push(*[Status(500, "overloaded")] * 3)
    first = runner.invoke(app, [*EVAL, "--out", str(out)])
    assert first.exit_code == 75, first.output
    assert "--resume --retry-errors" in " ".join(first.output.split())
    assert [r.retryable for r in read_records(out)] == [True]
    again = runner.invoke(app, [*EVAL, "--out", str(out), "--resume"])
    assert again.exit_code == 75  # a plain resume does not pretend the error is a result
    retried = runner.invoke(app, [*EVAL, "--out", str(out), "--resume", "--retry-errors"])
    assert retried.exit_code == 0, retried.output
    (record,) = read_records(out)
    assert record.error is None and not record.retryable
    assert len(read_records(out / "retried.jsonl")) == 1
    _key_nowhere(tmp_path, first.output, again.output, retried.output)
