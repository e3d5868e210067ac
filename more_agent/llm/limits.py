"""Hard limits on what an LLM or VLM sends back, applied where an answer enters our code.

A model (or a hostile server) can answer anything. Without limits one 5 MB "object name" is echoed
into every later prompt through the feedback and the history, grows the cache without bound and is
dumped to the terminal. Every backend's answer passes :class:`~more_agent.llm.client.ChatClient`,
which rejects an answer over :data:`MAX_ANSWER_CHARS` as invalid (recorded truncated); the parsers
reject names over :data:`MAX_NAME_CHARS`; the planners clip feedback and reasoning; errors and logs
clip server text. Each limit is far above what a valid answer needs (docs/llm.md, "Limits").
"""

from __future__ import annotations

import re

MAX_ANSWER_CHARS = 16_000
"""Longest answer accepted (about 4x what 1024 tokens hold); a longer one is an invalid answer."""

MAX_NAME_CHARS = 200
"""Longest skill, room or object name in an answer; real scene names are under 60 characters."""

MAX_REASONING_CHARS = 8_000
"""The answer's free-text reasoning is kept up to this length (answers may reason at length: half an answer)."""

MAX_FEEDBACK_CHARS = 500
"""Feedback of one action as the next prompt and the history show it."""

MAX_ECHO_CHARS = 2_000
"""An invalid answer echoed back to the model in a re-ask is clipped to this length."""

MAX_ERROR_CHARS = 1_000
"""Server or model text quoted in an error message (records, terminal)."""

MAX_LOG_CHARS = 2_000
"""One log message printed by the CLI."""


_CUT_NOTE = re.compile(r"\.\.\. \[\d+ more characters cut\]")


def clip(text: str, limit: int) -> str:
    """``text`` itself, or its first ``limit`` characters and a note of how many were cut.

    Idempotent: a text already clipped at ``limit`` comes back unchanged (a clipped answer read
    back from the cache keeps its original length in the note).
    """
    if len(text) <= limit or _CUT_NOTE.fullmatch(text, limit):
        return text
    return f"{text[:limit]}... [{len(text) - limit} more characters cut]"
