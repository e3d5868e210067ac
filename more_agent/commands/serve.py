"""``more-agent serve``: MORE's planner as an HTTP JSON service a robot stack calls each step
(``POST /v1/plan``; schema at ``/openapi.json``; docs/ros.md shows the loop a ROS 2 node runs)."""

from __future__ import annotations

from typing import Annotated

import typer

from more_agent.commands._common import err_console, user_errors_exit_2


@user_errors_exit_2
def serve(
    llm: Annotated[
        str | None, typer.Option(help="LLM spec such as openai:gpt-4o (default: the configured one).")
    ] = None,
    host: Annotated[
        str, typer.Option(help="Address to listen on (0.0.0.0: every interface; there is no auth).")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(min=1, max=65535, help="TCP port.")] = 8000,
) -> None:
    """Serve one MORE decision per request until Ctrl-C; without an LLM, say how to configure one."""
    from more_agent.interop.requirement import require
    from more_agent.service.decision import planner_clients

    clients = planner_clients(llm)
    uvicorn = require("uvicorn", "serve")
    from more_agent.service.app import create_app

    app = create_app(clients)
    err_console.print(f"planning with {clients.spec} on http://{host}:{port} (schema: /openapi.json)", highlight=False)
    uvicorn.run(app, host=host, port=port, log_level="warning")
