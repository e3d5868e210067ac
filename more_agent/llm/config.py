"""LLM configuration: one frozen pydantic model, loaded from a TOML/JSON file and the environment.

Precedence, lowest first: field defaults, the config file (its ``[llm]`` table if it has one, else
the whole document), then the environment (``OPENAI_BASE_URL``, ``OPENAI_API_KEY``, ``MORE_AGENT_*``,
see :mod:`more_agent.llm.constants`). The result is never mutated; derive variants with
``config.model_copy(update=...)``.
"""

from __future__ import annotations

import json
import os
import tomllib
from collections.abc import Mapping
from enum import StrEnum
from pathlib import Path
from urllib.parse import urlsplit

from pydantic import BaseModel, ConfigDict, Field, SecretStr, ValidationError, field_validator

from more_agent.errors import UserError
from more_agent.llm import constants as C
from more_agent.llm.errors import LLMConfigError
from more_agent.redaction import has_credentials
from more_agent.safe_files import read_bounded

MAX_CONFIG_BYTES = 1024 * 1024
"""Largest LLM config file read (a real one is under a kilobyte; ``/dev/zero`` is refused)."""
MAX_TIMEOUT_S = 3600.0
"""Longest ``timeout_s`` accepted: one request's whole wall-clock deadline."""


class CacheMode(StrEnum):
    """How the response cache is used."""

    ON = "on"
    """Read answers from the cache, ask the model on a miss and store its answer."""
    REFRESH = "refresh"
    """Always ask the model and overwrite the stored answer (bypass reads)."""
    OFF = "off"
    """Neither read nor write the cache."""
    REPLAY = "replay"
    """Only read the cache; a miss raises ReplayMiss (exact, offline repetition of a run)."""


class StructuredOutput(StrEnum):
    """Whether to send ``response_format`` with a JSON schema."""

    AUTO = "auto"
    """Send it; if the server rejects it (HTTP 400), fall back to text parsing for this client."""
    ALWAYS = "always"
    """Send it; a rejection is an error."""
    NEVER = "never"
    """Never send it; always parse the JSON out of the text."""


class NameEnums(StrEnum):
    """Whether answer schemas enumerate the names a request may use (:mod:`more_agent.llm.name_enums`)."""

    AUTO = "auto"
    """For llama.cpp (its grammar always applies), not for OpenAI-compatible endpoints."""
    ON = "on"
    """For every backend (OpenAI-compatible servers with ``json_schema`` structured output)."""
    OFF = "off"
    """Never: the schema fixes the shape, the re-ask path catches unknown names."""


class ModelPrice(BaseModel):
    """Price of one model in USD per million tokens."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    input_per_m: float = Field(ge=0, description="USD per 1M prompt tokens.")
    output_per_m: float = Field(ge=0, description="USD per 1M completion tokens.")


class LLMConfig(BaseModel):
    """Everything about how LLMs are reached; which LLM is the ``llm`` spec (or ``--llm``)."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    llm: str | None = Field(
        default=None, description="Default LLM spec ('openai:gpt-4o', 'llamacpp:PATH.gguf'); None = no LLM configured."
    )
    room_model: str | None = Field(
        default=None,
        description="LLM for room classification (paper: gpt-3.5-turbo): a spec such as 'openai:gpt-3.5-turbo', or a "
        "model name on the planning model's endpoint; None = the planning model (--room-llm).",
    )
    base_url: str | None = Field(
        default=None,
        description="OpenAI-compatible endpoint (OpenAI, Azure, vLLM, Ollama, llama.cpp); None = OpenAI's.",
    )
    api_key: SecretStr | None = Field(
        default=None, description="API key; better taken from OPENAI_API_KEY. Never written to caches or logs."
    )
    temperature: float = Field(default=C.DEFAULT_TEMPERATURE, ge=0, le=2, description="Sampling temperature.")
    max_tokens: int = Field(default=C.DEFAULT_MAX_TOKENS, gt=0, description="Upper bound on tokens of one answer.")
    seed: int | None = Field(default=None, description="Sampling seed sent to servers that honour it.")
    timeout_s: float = Field(
        default=C.DEFAULT_TIMEOUT_S,
        gt=0,
        le=MAX_TIMEOUT_S,
        description="Wall-clock seconds one HTTP request may take in all: connect, headers and body.",
    )
    max_retries: int = Field(default=C.DEFAULT_MAX_RETRIES, ge=0, description="Retries on timeouts, 429, 5xx, drops.")
    backoff_initial_s: float = Field(
        default=C.INITIAL_BACKOFF_S, ge=0, le=MAX_TIMEOUT_S, description="First sleep between retries."
    )
    backoff_max_s: float = Field(
        default=C.MAX_BACKOFF_S, ge=0, le=MAX_TIMEOUT_S, description="Longest sleep between retries."
    )
    structured_output: StructuredOutput = Field(
        default=StructuredOutput.AUTO, description="Send JSON schemas as response_format: auto, always or never."
    )
    name_enums: NameEnums = Field(
        default=NameEnums.AUTO,
        description="Enumerate valid skill, room and object names in answer schemas: auto (llama.cpp only), on, off.",
    )
    cache_mode: CacheMode = Field(default=CacheMode.ON, description="Response cache use: on, refresh, off, replay.")
    cache_path: Path = Field(default=C.DEFAULT_CACHE_PATH, description="sqlite file of the response cache.")
    cache_busy_timeout_s: float = Field(
        default=C.CACHE_BUSY_TIMEOUT_S,
        ge=0,
        le=MAX_TIMEOUT_S,
        description="How long to wait for another process's lock on the cache before the call fails (transient).",
    )
    prices: dict[str, ModelPrice] = Field(
        default_factory=dict, description="Extra or overriding prices per model name (see more_agent.llm.usage)."
    )
    llamacpp_n_ctx: int = Field(default=8192, gt=0, description="Context length for in-process GGUF models.")
    llamacpp_n_gpu_layers: int = Field(default=0, description="Layers offloaded to the GPU by llama.cpp (-1 = all).")
    llamacpp_n_threads: int | None = Field(
        default=None,
        gt=0,
        description="CPU threads of in-process GGUF models, prompts and generation; None = llama.cpp's choice.",
    )

    @field_validator("llm", "room_model")
    @classmethod
    def _no_credentials(cls, value: str | None) -> str | None:
        """Model names go into records, caches and run.json: one holding a key is refused."""
        if value is not None and has_credentials(value):
            raise ValueError("must not contain credentials; put the key in OPENAI_API_KEY")
        return value

    @field_validator("base_url")
    @classmethod
    def _http_url(cls, value: str | None) -> str | None:
        """An http(s) URL with a host and a valid port, without credentials (they would reach logs)."""
        if value is None:
            return None
        if has_credentials(value):
            raise ValueError(f"must not contain credentials; put the key in {C.ENV_API_KEY}")
        try:
            parts = urlsplit(value.strip())
            port = parts.port
        except ValueError as e:
            raise ValueError(f"{value!r} is not a URL: {e}") from None
        if parts.scheme not in ("http", "https") or not parts.hostname:
            raise ValueError(f"{value!r} is not an http(s) URL such as http://127.0.0.1:8080/v1")
        if port == 0:
            raise ValueError(f"{value!r} has port 0")
        return value.strip()

    @field_validator("api_key")
    @classmethod
    def _header_safe_key(cls, value: SecretStr | None) -> SecretStr | None:
        """A key is sent in an HTTP header: control characters (CR, LF) or non-ASCII cannot be."""
        if value is not None and not all(" " < c < "\x7f" for c in value.get_secret_value()):
            raise ValueError("holds a control character, a space or a non-ASCII character; check the key")
        return value

    def api_key_value(self) -> str | None:
        """The API key as plain text, for the one place that sends it."""
        return self.api_key.get_secret_value() if self.api_key is not None else None


def _read_file(path: Path) -> dict[str, object]:
    """The settings table of a TOML or JSON config file."""
    try:
        raw = read_bounded(path, what="LLM config", max_bytes=MAX_CONFIG_BYTES)
    except UserError as e:
        raise LLMConfigError(str(e)) from None
    try:
        doc = json.loads(raw) if path.suffix == ".json" else tomllib.loads(raw)
    except (ValueError, RecursionError) as e:
        raise LLMConfigError(f"cannot parse LLM config {path}: {str(e)[:200]}") from None
    if not isinstance(doc, dict):
        raise LLMConfigError(f"LLM config {path} must hold a table/object")
    table = doc.get("llm", doc)
    if not isinstance(table, dict):
        raise LLMConfigError(f"LLM config {path}: 'llm' must be a table/object")
    return table


def _env_settings(env: Mapping[str, str]) -> dict[str, object]:
    """Settings the environment overrides."""
    names = {
        C.ENV_BASE_URL: "base_url",
        C.ENV_API_KEY: "api_key",
        C.ENV_LLM: "llm",
        C.ENV_ROOM_MODEL: "room_model",
        C.ENV_NAME_ENUMS: "name_enums",
        C.ENV_CACHE_PATH: "cache_path",
        C.ENV_CACHE_MODE: "cache_mode",
    }
    return {field: env[var] for var, field in names.items() if env.get(var)}


def load_llm_config(
    path: Path | str | None = None,
    *,
    env: Mapping[str, str] | None = None,
    overrides: Mapping[str, object] | None = None,
) -> LLMConfig:
    """Build the config from ``path`` (or ``$MORE_AGENT_LLM_CONFIG``), the environment, then ``overrides``.

    ``env`` defaults to ``os.environ``; pass a dict in tests. ``overrides`` are for command-line flags.
    """
    env = os.environ if env is None else env
    file = Path(path) if path is not None else (Path(env[C.ENV_CONFIG]) if env.get(C.ENV_CONFIG) else None)
    settings: dict[str, object] = {}
    if file is not None:
        settings.update(_read_file(file))
    settings.update(_env_settings(env))
    settings.update(overrides or {})
    try:
        return LLMConfig.model_validate(settings)
    except ValidationError as e:
        where = f" (from {file} and the environment)" if file else " (from the environment)"
        problems = "; ".join(f"{'.'.join(map(str, err['loc']))}: {err['msg']}" for err in e.errors())
        raise LLMConfigError(f"invalid LLM config{where}: {problems}") from None
