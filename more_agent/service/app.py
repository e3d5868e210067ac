"""``create_app``: MORE's planner as an HTTP JSON service (FastAPI; ``more-agent serve``, the ``serve`` extra).

A robot stack calls ``POST /v1/plan`` once per step with its scene graph (ours, or Spark-DSG's JSON),
the task and the actions so far, and gets the next subpolicy (a
:class:`~more_agent.service.decision.Decision`). ``GET /v1/health`` names the LLM; ``/openapi.json``
and ``/docs`` hold the schema. Requests over ``max_body_bytes`` get 413 before they are read whole; a
body that is no graph MORE reads gets 422 with one line saying why; an LLM that fails gets 502 (504 on a
timeout). Error texts pass through the same redaction as logs. Decisions run one at a time.
"""

from __future__ import annotations

import threading
from typing import Any, Literal

from pydantic import BaseModel, Field

from more_agent.errors import UserError
from more_agent.interop.graph_file import graph_from_json
from more_agent.interop.requirement import require
from more_agent.llm import LLMError, LLMTimeout
from more_agent.llm.limits import MAX_LOG_CHARS, clip
from more_agent.planners.llm_planner import LLMClients
from more_agent.records import ActionRecord
from more_agent.redaction import redact
from more_agent.service.decision import Decision, decide

MAX_BODY_BYTES = 8 * 2**20
"""Largest request body accepted (a scene graph of a large building is a few hundred kB)."""

MAX_TASK_CHARS = 4000
"""Longest task text accepted."""

MAX_HISTORY = 500
"""Most actions a request may carry."""


class PlanRequest(BaseModel):
    """One step's question: give exactly one of ``graph`` and ``spark_dsg``."""

    task: str = Field(min_length=1, max_length=MAX_TASK_CHARS, description="The task in words.")
    graph: dict[str, Any] | None = Field(None, description="MORE's scene graph JSON (scene_graph.json of ingest).")
    spark_dsg: dict[str, Any] | None = Field(None, description="A Spark-DSG graph as its JSON (what Hydra saves).")
    label_map: dict[int, str] | None = Field(None, description="Spark-DSG graphs: semantic label -> class name.")
    history: list[ActionRecord] = Field(
        default_factory=list,
        max_length=MAX_HISTORY,
        description="The actions so far with their outcomes, oldest first.",
    )
    planner: Literal["more", "moma-llm", "moma-llm-sr"] = Field("more", description="LLM planner.")


class _BodyLimit:
    """ASGI middleware: 413 for a body longer than ``limit`` bytes (declared or streamed)."""

    def __init__(self, app: Any, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope: dict[str, Any], receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope.get("headers") or []).get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.limit:
            await _too_large(send, self.limit)
            return
        seen = 0

        async def counting_receive() -> dict[str, Any]:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                raise _TooLarge
            return message

        try:
            await self.app(scope, counting_receive, send)
        except _TooLarge:
            await _too_large(send, self.limit)


class _TooLarge(Exception):
    pass


async def _too_large(send: Any, limit: int) -> None:
    body = f'{{"detail": "request body over {limit} bytes"}}'.encode()
    await send(
        {
            "type": "http.response.start",
            "status": 413,
            "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())],
        }
    )
    await send({"type": "http.response.body", "body": body})


def _detail(e: Exception) -> str:
    return clip(redact(str(e)), MAX_LOG_CHARS)


def create_app(clients: LLMClients, *, max_body_bytes: int = MAX_BODY_BYTES) -> Any:
    """The FastAPI app deciding with ``clients`` (module docstring)."""
    fastapi = require("fastapi", "serve")
    responses = require("fastapi.responses", "serve")
    app = fastapi.FastAPI(
        title="more-agent", summary="MORE's filter and planner: one decision per robot step.", version="1"
    )
    lock = threading.Lock()

    @app.exception_handler(UserError)
    async def bad_input(request: Any, exc: UserError) -> Any:
        return responses.JSONResponse(status_code=422, content={"detail": _detail(exc)})

    @app.exception_handler(LLMError)
    async def llm_failed(request: Any, exc: LLMError) -> Any:
        status = 504 if isinstance(exc, LLMTimeout) else 502
        return responses.JSONResponse(
            status_code=status, content={"detail": f"LLM error ({type(exc).__name__}): {_detail(exc)}"}
        )

    @app.get("/v1/health")
    def health() -> dict[str, str]:
        """The service is up; the LLM it plans with."""
        return {"status": "ok", "llm": clients.spec}

    @app.post("/v1/plan", response_model=Decision)
    def plan(request: PlanRequest) -> Decision:
        """The next subpolicy for the robot, from its scene graph, its task and its history."""
        if (request.graph is None) == (request.spark_dsg is None):
            raise UserError("give exactly one of 'graph' (MORE's scene graph) and 'spark_dsg' (a Spark-DSG JSON graph)")
        data = request.graph if request.graph is not None else request.spark_dsg
        graph = graph_from_json(data, request.label_map, source="graph" if request.graph is not None else "spark_dsg")
        with lock:
            return decide(graph, request.task, request.history, clients, planner=request.planner)

    app.add_middleware(_BodyLimit, limit=max_body_bytes)
    return app
