"""Defaults of the LLM layer in one place: timeouts, retries, backoff, cache and environment names.

Everything tunable here is also a field of :class:`more_agent.llm.config.LLMConfig`; these are the
values a config starts from.
"""

from __future__ import annotations

from pathlib import Path

DEFAULT_TIMEOUT_S = 60.0
"""Seconds one HTTP request may take before it counts as a timeout."""

DEFAULT_MAX_RETRIES = 3
"""Retries after the first attempt on timeouts, 429, 5xx and connection errors."""

INITIAL_BACKOFF_S = 0.5
"""Sleep before the first retry; doubled on each further retry."""

MAX_BACKOFF_S = 8.0
"""Upper bound of one sleep between retries, a server's retry-after included."""

BACKOFF_JITTER = 0.25
"""Random extra share of each sleep (0.25 = up to 25 % longer) so parallel workers spread out."""

RETRYABLE_STATUS = frozenset({408, 409, 429, 500, 502, 503, 504})
"""HTTP statuses worth retrying; any other status error is raised at once."""

DEFAULT_TEMPERATURE = 0.0
"""Sampling temperature; 0 keeps runs as repeatable as the server allows."""

DEFAULT_MAX_TOKENS = 1024
"""Upper bound on tokens of one answer."""

OPENAI_BASE_URL = "https://api.openai.com/v1"
"""The official endpoint; the only one for which a missing API key is an error."""

PLACEHOLDER_API_KEY = "not-needed"
"""Key sent to custom endpoints (local servers) when none is configured."""

DEFAULT_CACHE_PATH = Path.home() / ".cache" / "more-agent" / "llm-cache.sqlite"
"""Where the sqlite response cache lives unless configured otherwise."""

CACHE_BUSY_TIMEOUT_S = 30.0
"""How long a process waits for another one's sqlite write lock."""

CACHE_KEY_VERSION = 1
"""Bumped whenever the cache key layout changes, so old entries stop matching."""

ENV_BASE_URL = "OPENAI_BASE_URL"
ENV_API_KEY = "OPENAI_API_KEY"
ENV_CONFIG = "MORE_AGENT_LLM_CONFIG"
"""Path of an LLM config file (TOML or JSON) read when no path is given explicitly."""
ENV_LLM = "MORE_AGENT_LLM"
"""Default LLM spec, e.g. ``openai:gpt-4o``; unset means no LLM is configured."""
ENV_ROOM_MODEL = "MORE_AGENT_ROOM_MODEL"
ENV_NAME_ENUMS = "MORE_AGENT_NAME_ENUMS"
ENV_CACHE_PATH = "MORE_AGENT_LLM_CACHE"
ENV_CACHE_MODE = "MORE_AGENT_LLM_CACHE_MODE"
