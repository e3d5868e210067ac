"""``more-agent plan``: one decision on a graph file through a real local OpenAI-compatible server; without
an LLM, how to configure one; never a privileged planner."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.interop.spark_dsg import from_spark_dsg
from more_agent.records import ActionRecord
from tests.fakes.decision_brain import SPEC, DecisionBrain
from tests.fakes.openai_server import FakeOpenAIServer, Status
from tests.interop.hydra import APARTMENT_LABELS, apartment, kitchen_and_hall

KEY = "sk-plan-secret-123456"


@pytest.fixture
def llm_env(tmp_path, monkeypatch):
    def point_at(server: FakeOpenAIServer) -> None:
        for name, value in {"OPENAI_BASE_URL": server.base_url, "OPENAI_API_KEY": KEY,
                            "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite")}.items():
            monkeypatch.setenv(name, value)
    monkeypatch.delenv("MORE_AGENT_LLM", raising=False)
    config = tmp_path / "llm.toml"
    config.write_text("timeout_s = 5.0\nmax_retries = 0\n")
    monkeypatch.setenv("MORE_AGENT_LLM_CONFIG", str(config))
    for name in ("OPENAI_BASE_URL", "OPENAI_API_KEY"):
        monkeypatch.delenv(name, raising=False)
    return point_at


def test_plan_on_a_spark_dsg_file_prints_the_decision_as_json(tmp_path, llm_env):
    graph = tmp_path / "hydra.sparkdsg"
    kitchen_and_hall().save(str(graph), include_mesh=False)
    history = tmp_path / "history.json"
    history.write_text(json.dumps([ActionRecord(step=0, name="explore", arguments=["kitchen_0"], ok=True,
                                                feedback="explored").model_dump()]))
    with FakeOpenAIServer(responder=DecisionBrain(["cup A"], "go_to_and_grasp", "cup A")) as server:
        llm_env(server)
        result = CliRunner().invoke(app, ["plan", "--graph", str(graph), "--task", "put the cup in the fridge",
                                          "--history", str(history), "--llm", SPEC, "--json"])
        assert result.exit_code == 0, result.output
        plan_prompt = server.requests[-1].body["messages"][-1]["content"]
    decision = json.loads(result.stdout)
    assert (decision["skill"], decision["arguments"]) == ("go_to_and_grasp", ["kitchen_0", "cup A"])
    assert "explore(kitchen_0)" in plan_prompt and "put the cup in the fridge" in plan_prompt
    assert KEY not in result.output and not any(KEY.encode() in p.read_bytes() for p in tmp_path.rglob("*") if p.is_file())


@pytest.mark.slow
def test_plan_json_on_the_hydra_apartment_is_clean_json_on_stdout(tmp_path, llm_env):
    """A real process: spark-dsg's C++ warning about the file's old encoding must not reach stdout."""
    label_map = tmp_path / "labels.json"
    label_map.write_text(json.dumps({str(k): v for k, v in APARTMENT_LABELS.items()}))
    with FakeOpenAIServer(responder=DecisionBrain(["table B"], "go_to_and_place_ontop", "table B")) as server:
        llm_env(server)
        done = subprocess.run([sys.executable, "-c", "from more_agent.cli import app; app()", "plan", "--graph",
                               str(apartment(tmp_path)), "--label-map", str(label_map), "--task", "put it on table B",
                               "--llm", SPEC, "--json"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    decision = json.loads(done.stdout)
    assert (decision["skill"], decision["arguments"]) == ("go_to_and_place_ontop", ["kitchen_0", "table B"])
    assert "outdated encoding" in done.stderr


def test_plan_reads_our_own_graph_json(tmp_path, llm_env):
    ours = tmp_path / "scene_graph.json"
    ours.write_text(from_spark_dsg(kitchen_and_hall()).model_dump_json())
    with FakeOpenAIServer(responder=DecisionBrain(["fridge A"], "go_to_and_open", "fridge A")) as server:
        llm_env(server)
        result = CliRunner().invoke(app, ["plan", "--graph", str(ours), "--task", "open the fridge", "--llm", SPEC,
                                          "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["arguments"] == ["kitchen_1", "fridge A"]


def test_without_an_llm_plan_says_how_to_configure_one(tmp_path, llm_env):
    result = CliRunner().invoke(app, ["plan", "--graph", str(tmp_path / "missing.json"), "--task", "x"])
    assert result.exit_code == 2
    assert "--llm openai:MODEL" in result.output and "never run on real data" in result.output


def test_plan_refuses_privileged_planners_and_bad_files(tmp_path, llm_env):
    result = CliRunner().invoke(app, ["plan", "--graph", "g.json", "--task", "x", "--planner", "oracle", "--llm", SPEC])
    assert result.exit_code == 2 and "unknown LLM planner" in result.output
    bad = tmp_path / "bad.json"
    bad.write_text("[1, 2]")
    with FakeOpenAIServer(responder=DecisionBrain([], "done", "")) as server:
        llm_env(server)
        result = CliRunner().invoke(app, ["plan", "--graph", str(bad), "--task", "x", "--llm", SPEC])
    assert result.exit_code == 2 and "a scene graph is a JSON object" in result.output


def test_an_llm_that_fails_is_one_error_line_with_the_key_redacted(tmp_path, llm_env):
    graph = tmp_path / "graph.json"
    graph.write_text(from_spark_dsg(kitchen_and_hall()).model_dump_json())
    with FakeOpenAIServer([Status(401, message=f"bad key {KEY}")]) as server:
        llm_env(server)
        result = CliRunner().invoke(app, ["plan", "--graph", str(graph), "--task", "x", "--llm", SPEC])
    assert result.exit_code == 1 and "error: LLM error (LLMAuthError)" in result.output
    assert KEY not in result.output and "Traceback" not in result.output
