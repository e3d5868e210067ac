"""Naming an LLM on the command line (``openai:MODEL``, ``llamacpp:PATH.gguf``) and building its client."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from more_agent.errors import closest_names
from more_agent.llm.cache import ResponseCache, check_cache_path
from more_agent.llm.client import Backend, ChatClient
from more_agent.llm.config import CacheMode, LLMConfig
from more_agent.llm.errors import BadLLMSpec
from more_agent.llm.local_models import BUNDLED_MODELS, gguf_path, is_bundled
from more_agent.llm.name_enums import uses_name_enums
from more_agent.redaction import has_credentials

BACKEND_KINDS = ("openai", "llamacpp")
SPEC_HELP = f"use openai:MODEL (e.g. openai:gpt-4o), llamacpp:PATH.gguf or llamacpp:{'|'.join(BUNDLED_MODELS)}"


class LLMSpec(BaseModel):
    """Which LLM: a backend kind and a model name (openai) or GGUF file path or bundled model name (llamacpp)."""

    model_config = ConfigDict(frozen=True)

    kind: Literal["openai", "llamacpp"] = Field(description="Backend family.")
    model: str = Field(description="Model name at the endpoint, or path of the .gguf file, or a bundled model's name.")

    def __str__(self) -> str:
        return f"{self.kind}:{self.model}"


def parse_llm_spec(spec: str) -> LLMSpec:
    """Parse ``KIND:MODEL``; raises BadLLMSpec saying what is wrong and what to write instead.

    A spec holding credentials (``?api_key=...``, an ``sk-...`` key) is refused: specs are written
    into records, caches and run.json; keys belong in the environment.
    """
    if has_credentials(spec):
        raise BadLLMSpec("the LLM spec must not contain credentials; set them in the environment (e.g. OPENAI_API_KEY)")
    kind, sep, model = spec.strip().partition(":")
    kind, model = kind.strip().lower(), model.strip()
    if not sep:
        raise BadLLMSpec(f"LLM spec {spec!r} has no backend prefix; {SPEC_HELP}")
    if kind not in BACKEND_KINDS:
        close = closest_names(kind, BACKEND_KINDS)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise BadLLMSpec(f"unknown LLM backend {kind!r} in {spec!r}{hint}; {SPEC_HELP}")
    if not model:
        raise BadLLMSpec(f"LLM spec {spec!r} names no model; {SPEC_HELP}")
    if kind == "llamacpp" and not model.lower().endswith(".gguf") and not is_bundled(model):
        raise BadLLMSpec(f"llamacpp model {model!r} is not a .gguf file nor a bundled model; {SPEC_HELP}")
    return LLMSpec(kind=kind, model=model)


def configured_llm(config: LLMConfig, cli_spec: str | None = None) -> LLMSpec | None:
    """The LLM to use: ``--llm`` if given, else the config's/``MORE_AGENT_LLM``'s, else None (run the oracle)."""
    spec = cli_spec or config.llm
    return parse_llm_spec(spec) if spec else None


def llm_configured(config: LLMConfig, cli_spec: str | None = None) -> bool:
    """Whether any LLM is configured; False means the default planner is the oracle."""
    return bool(cli_spec or config.llm)


def room_spec(spec: LLMSpec, config: LLMConfig) -> LLMSpec:
    """The LLM for room classification (the paper: GPT-3.5 Turbo, GPT-4o for the rest): ``config.room_model``
    as a full spec (``openai:gpt-3.5-turbo``, ``llamacpp:smollm2``), or a bare model name on the planning
    model's OpenAI-compatible endpoint; the planning model ``spec`` when it is unset."""
    room = config.room_model
    if room and room.partition(":")[0].strip().lower() in BACKEND_KINDS:
        return parse_llm_spec(room)
    if spec.kind == "openai" and room:
        return LLMSpec(kind="openai", model=room)
    return spec


def make_backend(spec: LLMSpec, config: LLMConfig) -> Backend:
    """The backend for ``spec`` (imports the backend module only now)."""
    if spec.kind == "openai":
        from more_agent.llm.openai_backend import OpenAIBackend

        return OpenAIBackend.from_config(spec.model, config, require_key=config.cache_mode is not CacheMode.REPLAY)
    from more_agent.llm.llamacpp_backend import LlamaCppBackend

    generates = config.cache_mode is not CacheMode.REPLAY
    return LlamaCppBackend.from_config(
        gguf_path(spec.model, require_installed=generates), config, require_model=generates
    )


def make_client(spec: LLMSpec | str, config: LLMConfig) -> ChatClient:
    """A ready client for ``spec`` with the configured cache mode; raises LLMConfigError subclasses."""
    spec = parse_llm_spec(spec) if isinstance(spec, str) else spec
    cache = None
    if config.cache_mode is not CacheMode.OFF:
        check_cache_path(config.cache_path, write=config.cache_mode is not CacheMode.REPLAY)
        cache = ResponseCache(config.cache_path, busy_timeout_s=config.cache_busy_timeout_s)
    backend = make_backend(spec, config)
    return ChatClient(
        backend,
        cache=cache,
        cache_mode=config.cache_mode,
        temperature=config.temperature,
        max_tokens=config.max_tokens,
        seed=config.seed,
        prices=config.prices,
        name_enums=uses_name_enums(config, backend.kind),
    )
