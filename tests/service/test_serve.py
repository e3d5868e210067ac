"""``more-agent serve``'s app under a real uvicorn server, called through a real HTTP client (urllib):
decisions, the OpenAPI schema, 4xx for malformed graphs and oversized bodies, 502 for a failing LLM."""

from __future__ import annotations

import json
import socket
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from typing import Any

import pytest
import uvicorn
from typer.testing import CliRunner

from more_agent.cli import app as cli
from more_agent.service.app import create_app
from tests.fakes.decision_brain import DecisionBrain, clients
from tests.fakes.openai_server import FakeOpenAIServer, Status
from tests.interop.hydra import kitchen_and_hall

KEY = "sk-serve-secret-7890"


class Served:
    """A uvicorn server running the app on a free local port, in a thread."""

    def __init__(self, app: Any) -> None:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=self.port, log_level="error"))
        self.thread = threading.Thread(target=self.server.run, daemon=True)

    def __enter__(self) -> Served:
        self.thread.start()
        deadline = time.monotonic() + 10
        while not self.server.started and time.monotonic() < deadline:
            time.sleep(0.02)
        assert self.server.started
        return self

    def __exit__(self, *exc: object) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=10)

    def call(self, method: str, path: str, body: bytes | None = None) -> tuple[int, dict[str, Any]]:
        request = urllib.request.Request(f"http://127.0.0.1:{self.port}{path}", data=body, method=method,
                                         headers={"content-type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=10) as response:
                return response.status, json.loads(response.read())
        except urllib.error.HTTPError as e:
            return e.code, json.loads(e.read())


@pytest.fixture
def service(tmp_path) -> Iterator[tuple[Served, FakeOpenAIServer]]:
    brain = DecisionBrain(["cup A", "table A"], "go_to_and_grasp", "cup A")
    with FakeOpenAIServer(responder=brain) as llm, Served(create_app(clients(llm.base_url, tmp_path / "c.sqlite"),
                                                                     max_body_bytes=200_000)) as served:
        yield served, llm


def _our_graph() -> dict[str, Any]:
    from more_agent.interop.spark_dsg import from_spark_dsg

    return json.loads(from_spark_dsg(kitchen_and_hall()).model_dump_json())


def test_a_robot_step_gets_the_next_subpolicy_for_our_graph_and_for_a_spark_dsg_one(service, tmp_path):
    served, _ = service
    history = [{"step": 0, "name": "explore", "arguments": ["kitchen_0"], "ok": True, "feedback": "explored"}]
    status, decision = served.call("POST", "/v1/plan", json.dumps(
        {"task": "put the cup in the fridge", "graph": _our_graph(), "history": history}).encode())
    assert status == 200, decision
    assert (decision["skill"], decision["arguments"]) == ("go_to_and_grasp", ["kitchen_0", "cup A"])
    path = tmp_path / "hydra.json"
    kitchen_and_hall().save(str(path), include_mesh=False)
    status, decision = served.call("POST", "/v1/plan", json.dumps(
        {"task": "put the cup in the fridge", "spark_dsg": json.loads(path.read_text())}).encode())
    assert status == 200 and decision["arguments"] == ["kitchen_0", "cup A"], decision
    assert served.call("GET", "/v1/health")[1]["llm"] == "openai:fake-model"


def test_the_openapi_schema_describes_the_plan_endpoint(service):
    status, schema = service[0].call("GET", "/openapi.json")
    assert status == 200 and "/v1/plan" in schema["paths"]
    assert {"task", "graph", "spark_dsg", "history"} <= set(schema["components"]["schemas"]["PlanRequest"]["properties"])


@pytest.mark.parametrize(("body", "status", "text"), [
    (b"{not json", 422, "JSON"),
    (json.dumps({"task": "x"}).encode(), 422, "exactly one of 'graph'"),
    (json.dumps({"task": "x", "graph": {"schema_version": 2, "step": 0}}).encode(), 422, "not a valid MORE scene graph"),
    (json.dumps({"task": "x", "graph": {"schema_version": 99}}).encode(), 422, "schema version 99"),
    (json.dumps({"task": "x", "spark_dsg": {"nodes": "garbage"}}).encode(), 422, "Spark-DSG"),
    (json.dumps({"task": "", "graph": {}}).encode(), 422, "task"),
    (b"{" + b" " * 300_000 + b"}", 413, "over 200000 bytes"),
])
def test_malformed_requests_get_a_clear_4xx(service, body, status, text):
    got, answer = service[0].call("POST", "/v1/plan", body)
    assert got == status and text in json.dumps(answer), answer


def test_a_failing_llm_is_a_502_with_the_key_redacted(tmp_path):
    with FakeOpenAIServer([Status(401, message=f"bad key {KEY}")]) as llm, \
            Served(create_app(clients(llm.base_url, tmp_path / "c.sqlite"))) as served:
        status, answer = served.call("POST", "/v1/plan", json.dumps({"task": "x", "graph": _our_graph()}).encode())
    assert status == 502 and "LLMAuthError" in answer["detail"] and KEY not in answer["detail"]


def test_serve_without_an_llm_says_how_to_configure_one(monkeypatch, tmp_path):
    for name in ("MORE_AGENT_LLM", "OPENAI_API_KEY", "OPENAI_BASE_URL"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("MORE_AGENT_LLM_CONFIG", str(tmp_path / "llm.toml"))
    (tmp_path / "llm.toml").write_text("")
    result = CliRunner().invoke(cli, ["serve"])
    assert result.exit_code == 2 and "--llm openai:MODEL" in result.output
