"""LLM layer: clients (OpenAI-compatible HTTP, in-process llama.cpp), sqlite cache and replay, prompts,
answer parsing and validation.

Typical use by a planner::

    config = load_llm_config()                      # file + environment
    client = make_client(parse_llm_spec("openai:gpt-4o"), config)
    out = ask_validated(client, plan_messages(...), PlanAnswer,
                        lambda a: parse_plan_answer(a, SKILLS, rooms, objects), purpose="plan")
    out.value  # PlannedAction

The skills are those of the table :data:`more_agent.skills.SKILLS`.

Importing this package builds no client and does not import the ``openai`` SDK.
"""

from more_agent.llm.answers import (
    FilterAnswer,
    FilterResult,
    PlanAnswer,
    PlannedAction,
    RoomLabelAnswer,
    RoomObjects,
)
from more_agent.llm.cache import ResponseCache
from more_agent.llm.client import Backend, ChatClient, ChatRequest, Generation, LLMClient
from more_agent.llm.completion import ChatMessage, Completion, TokenUsage
from more_agent.llm.config import CacheMode, LLMConfig, ModelPrice, StructuredOutput, load_llm_config
from more_agent.llm.errors import (
    BadLLMSpec,
    InvalidAnswer,
    LLMAuthError,
    LLMBadRequest,
    LLMConfigError,
    LLMConnectionError,
    LLMError,
    LLMRateLimited,
    LLMServerError,
    LLMStatusError,
    LLMTimeout,
    LLMTransportError,
    MissingAPIKey,
    MissingExtra,
    OversizeAnswer,
    ReplayMiss,
    Unparseable,
)
from more_agent.llm.jsontext import extract_json
from more_agent.llm.parsing import parse_filter_answer, parse_plan_answer, parse_room_label
from more_agent.llm.prompts import filter_messages, history_text, plan_messages, render_prompt, room_messages
from more_agent.llm.reask import Validated, ask_validated
from more_agent.llm.spec import LLMSpec, configured_llm, llm_configured, make_client, parse_llm_spec, room_spec
from more_agent.llm.usage import UsageMeter

__all__ = [
    "Backend",
    "BadLLMSpec",
    "CacheMode",
    "ChatClient",
    "ChatMessage",
    "ChatRequest",
    "Completion",
    "FilterAnswer",
    "FilterResult",
    "Generation",
    "InvalidAnswer",
    "LLMAuthError",
    "LLMBadRequest",
    "LLMClient",
    "LLMConfig",
    "LLMConfigError",
    "LLMConnectionError",
    "LLMError",
    "LLMRateLimited",
    "LLMServerError",
    "LLMSpec",
    "LLMStatusError",
    "LLMTimeout",
    "LLMTransportError",
    "MissingAPIKey",
    "MissingExtra",
    "OversizeAnswer",
    "ModelPrice",
    "PlanAnswer",
    "PlannedAction",
    "ReplayMiss",
    "ResponseCache",
    "RoomLabelAnswer",
    "RoomObjects",
    "StructuredOutput",
    "TokenUsage",
    "Unparseable",
    "UsageMeter",
    "Validated",
    "ask_validated",
    "configured_llm",
    "extract_json",
    "filter_messages",
    "history_text",
    "llm_configured",
    "load_llm_config",
    "make_client",
    "parse_filter_answer",
    "parse_llm_spec",
    "parse_plan_answer",
    "parse_room_label",
    "plan_messages",
    "render_prompt",
    "room_messages",
    "room_spec",
]
