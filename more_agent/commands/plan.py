"""``more-agent plan --graph FILE --task TEXT``: one MORE decision on a scene graph file (ours or Spark-DSG's).

Prints the chosen subpolicy with its arguments and the filtered scene, or with ``--json`` the whole
:class:`~more_agent.service.decision.Decision`. Without an LLM it says how to configure one (exit 2):
the privileged planners never run on real data. An LLM that fails: one error line, exit 75 when it is
transient (unreachable, timeout, 5xx, 429), 1 otherwise.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.text import Text

from more_agent.commands._common import EXIT_FAILED, EXIT_RETRYABLE, console, print_error, user_errors_exit_2
from more_agent.errors import UserError

if TYPE_CHECKING:
    from more_agent.records import ActionRecord


def read_history(path: Path) -> list[ActionRecord]:
    """A history file: a JSON list of actions (``episode.json``'s ``actions``), or an ``episode.json``."""
    from pydantic import TypeAdapter, ValidationError

    from more_agent.records import ActionRecord

    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        actions = data.get("actions", []) if isinstance(data, dict) else data
        return TypeAdapter(list[ActionRecord]).validate_python(actions)
    except (OSError, ValueError, ValidationError) as e:
        raise UserError(
            f"--history {path}: expected a JSON list of actions "
            f"({{step, name, arguments, ok, feedback}}): {' '.join(str(e).splitlines()[:2])}"
        ) from None


@user_errors_exit_2
def plan(
    graph: Annotated[
        Path,
        typer.Option(help="Scene graph: ours (scene_graph.json of ingest) or Spark-DSG (.json, .sparkdsg, .bson)."),
    ],
    task: Annotated[str, typer.Option(help="The task in words, e.g. 'put the apple in the fridge'.")],
    history: Annotated[Path | None, typer.Option(help="JSON list of the actions so far (as in episode.json).")] = None,
    llm: Annotated[
        str | None, typer.Option(help="LLM spec such as openai:gpt-4o (default: the configured one).")
    ] = None,
    planner: Annotated[str, typer.Option(help="LLM planner: more, moma-llm or moma-llm-sr.")] = "more",
    label_map: Annotated[Path | None, typer.Option(help="Spark-DSG graphs: JSON {semantic label: class name}.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the decision as JSON.")] = False,
) -> None:
    """One MORE decision: room labels, filtered scene, and the next subpolicy with its arguments."""
    from more_agent.errors import unknown_name_error
    from more_agent.interop.graph_file import read_graph, read_label_map
    from more_agent.llm.errors import LLMAuthError, LLMBadRequest, LLMError, LLMTransportError
    from more_agent.service.decision import LLM_PLANNERS, decide, planner_clients

    if planner not in LLM_PLANNERS:
        raise unknown_name_error("LLM planner (plan never runs a privileged one)", planner, LLM_PLANNERS)
    clients = planner_clients(llm)  # no LLM: says how to configure one, before reading anything
    scene_graph = read_graph(graph, read_label_map(label_map) if label_map else None)
    actions = read_history(history) if history is not None else []
    try:
        decision = decide(scene_graph, task, actions, clients, planner=planner)
    except LLMError as e:
        print_error(f"LLM error ({type(e).__name__}): {e}")
        transient = isinstance(e, LLMTransportError) and not isinstance(e, (LLMAuthError, LLMBadRequest))
        raise typer.Exit(code=EXIT_RETRYABLE if transient else EXIT_FAILED) from None
    if as_json:
        print(decision.model_dump_json(indent=2))
        return
    console.print(Text(f"{decision.skill}({', '.join(decision.arguments)})", style="bold"))
    console.print(Text(f"why: {decision.reasoning}"))
    console.print(Text(f"scene MORE kept:\n{decision.filtered_scene}"))
