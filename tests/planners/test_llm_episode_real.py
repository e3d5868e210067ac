"""Short ``more`` episodes with a real model (SmolLM2-135M-Instruct, the ``local`` extra), from the CLI.

Once in this process (``--llm llamacpp:smollm2``) and once behind llama-cpp-python's own
OpenAI-compatible server driven by our ``openai:`` backend through ``OPENAI_BASE_URL``. Each episode is
recorded with ``more-agent run``; then every cached answer must parse against the schema it was asked
for with the token count the model's tokenizer gives, and ``more-agent eval`` in replay mode must
repeat the episode identically with the model gone. Marked ``real_llm`` (run by ``.ci/run``).
"""

from __future__ import annotations

import json
import socket
import sqlite3
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import jsonschema
import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.llm import FilterAnswer, LLMConfig, PlanAnswer, RoomLabelAnswer, make_client
from more_agent.llm.jsontext import json_schema_of
from more_agent.llm.llamacpp_backend import GGUF_CHAT_FORMAT, LlamaCppBackend, _load
from more_agent.llm.local_models import bundled_model_path
from more_agent.records import EpisodeRecord

pytestmark = pytest.mark.real_llm

KITCHEN = Path(__file__).parents[1] / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"
STEPS = 2
"""High-level steps per episode: enough for room labels, filter, plans and feedback, short on 2 cores."""
ANSWERS = {json_schema_of(m)["title"]: m for m in (RoomLabelAnswer, FilterAnswer, PlanAnswer)}
"""Answer models by schema title: requests may carry per-request name enums (``llm/name_enums.py``)."""
runner = CliRunner()


def _cli(args: list[str], env: dict[str, str]) -> None:
    result = runner.invoke(app, args, env=env, catch_exceptions=False)
    assert result.exit_code == 0, result.output


def _cached_rows(cache: Path) -> list[tuple[dict, str, int, int]]:
    with sqlite3.connect(cache) as db:
        rows = db.execute("SELECT request, text, prompt_tokens, completion_tokens FROM responses").fetchall()
    return [(json.loads(r), text, p, c) for r, text, p, c in rows]


def _outcome(record: EpisodeRecord) -> dict:
    """Everything of a record that a replay must repeat exactly (timings and LLM wait times differ)."""
    return record.model_dump(exclude={"timings", "llm_usage"})


def _record_check_replay(tmp_path: Path, llm: str, env: dict[str, str], monkeypatch: pytest.MonkeyPatch) -> EpisodeRecord:
    """Record an episode with ``more-agent run``, check its answers and usage, stop the model, replay with ``eval``."""
    monkeypatch.setattr("more_agent.eval.episode.MAX_HIGH_LEVEL_STEPS", STEPS)
    cache = tmp_path / "cache.sqlite"
    env = {**env, "MORE_AGENT_LLM_CACHE": str(cache), "MORE_AGENT_LLM_CACHE_MODE": "on"}
    _cli(["run", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", llm, "--out", str(tmp_path / "ep")], env)
    record = EpisodeRecord.model_validate_json((tmp_path / "ep" / "episode.json").read_text())
    assert record.traceback is None and record.error in (None, f"step limit of {STEPS} high-level steps reached")
    assert 1 <= record.high_level_steps <= STEPS and record.llm == llm

    rows = _cached_rows(cache)
    usage = record.llm_usage
    assert usage.calls == len(rows) + usage.cache_hits >= 2  # room label(s), filter, plan at the least
    tokenizer = LlamaCppBackend(bundled_model_path("smollm2"))
    for request, text, prompt_tokens, completion_tokens in rows:
        schema = request["schema"]
        ANSWERS[schema["title"]].model_validate_json(text)  # every answer parses as its model
        jsonschema.validate(json.loads(text), schema)  # and keeps to the schema sent, name enums included
        assert prompt_tokens == tokenizer.prompt_tokens(request["messages"]) and completion_tokens > 0
    assert usage.prompt_tokens >= sum(r[2] for r in rows) and usage.completion_tokens >= sum(r[3] for r in rows)
    assert usage.seconds > 0 and record.timings["llm"] == pytest.approx(usage.seconds, abs=1e-5)
    return record


def _replay(tmp_path: Path, llm: str, env: dict[str, str], first: EpisodeRecord) -> None:
    """``more-agent eval`` of the same episode in replay mode: the same record, every answer from the cache."""
    env = {**env, "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite"), "MORE_AGENT_LLM_CACHE_MODE": "replay"}
    out = tmp_path / "replay"
    _cli(["eval", "--tasks", TASK, "--scene", str(KITCHEN), "--planner", "more", "--llm", llm, "--out", str(out),
          "--no-progress"], env)
    (line,) = (out / "episodes.jsonl").read_text().splitlines()
    again = EpisodeRecord.model_validate_json(line)
    assert _outcome(again) == _outcome(first)
    assert again.llm_usage.cache_hits == again.llm_usage.calls == first.llm_usage.calls
    assert (again.llm_usage.prompt_tokens, again.llm_usage.completion_tokens) == (
        first.llm_usage.prompt_tokens, first.llm_usage.completion_tokens)


def test_in_process_episode_records_real_answers_and_replays_without_the_model(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = _record_check_replay(tmp_path, "llamacpp:smollm2", {}, monkeypatch)
    _load.cache_clear()
    monkeypatch.setitem(sys.modules, "llama_cpp", None)  # the model cannot even be imported now
    _replay(tmp_path, "llamacpp:smollm2", {}, first)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextmanager
def llama_cpp_server(model: Path, log: Path, *, alias: str, timeout_s: float = 120.0) -> Iterator[str]:
    """``python -m llama_cpp.server`` on a free loopback port with the GGUF's chat template; yields its base URL."""
    port = _free_port()
    args = [sys.executable, "-m", "llama_cpp.server", "--model", str(model), "--model_alias", alias,
            "--host", "127.0.0.1", "--port", str(port), "--n_ctx", "8192", "--chat_format", GGUF_CHAT_FORMAT]
    with log.open("wb") as out:
        proc = subprocess.Popen(args, stdout=out, stderr=subprocess.STDOUT)
    base_url = f"http://127.0.0.1:{port}/v1"
    try:
        deadline = time.monotonic() + timeout_s
        while True:
            assert proc.poll() is None, f"llama_cpp.server exited with {proc.returncode}:\n{log.read_text()[-3000:]}"
            assert time.monotonic() < deadline, f"llama_cpp.server not up after {timeout_s} s:\n{log.read_text()[-3000:]}"
            try:
                with urllib.request.urlopen(f"{base_url}/models", timeout=2) as resp:
                    if resp.status == 200:
                        break
            except OSError:
                time.sleep(0.5)
        yield base_url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_episode_through_llama_cpps_openai_server_records_and_replays_without_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    with llama_cpp_server(bundled_model_path("smollm2"), tmp_path / "server.log", alias="smollm2") as base_url:
        env = {"OPENAI_BASE_URL": base_url}
        first = _record_check_replay(tmp_path, "openai:smollm2", env, monkeypatch)
        # our client asked in OpenAI's json_schema form first; the server's 422 moved it to its json_object form
        probe = make_client("openai:smollm2", LLMConfig(base_url=base_url, cache_mode="off", max_tokens=32))
        probe.complete([{"role": "user", "content": "Name a room."}], schema=RoomLabelAnswer)
        assert probe.backend.schema_format == "json_object"
    _replay(tmp_path, "openai:smollm2", {"OPENAI_BASE_URL": base_url}, first)  # the server is gone
