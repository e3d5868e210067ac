"""Typed errors of the LLM layer, one class per cause.

Two families: :class:`LLMError` for things that go wrong while talking to a model (transport,
server, answer content) and :class:`LLMConfigError` (a :class:`~more_agent.errors.UserError`) for
things the user must fix (bad spec, missing key, missing extra). Callers catch by cause, e.g.
``except (LLMTimeout, LLMRateLimited)``; the episode loop catches :class:`InvalidAnswer`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from more_agent.errors import UserError
from more_agent.llm.limits import MAX_ANSWER_CHARS, MAX_ERROR_CHARS, clip
from more_agent.redaction import for_terminal

if TYPE_CHECKING:
    from more_agent.llm.completion import Completion


class LLMError(Exception):
    """Base class of everything that goes wrong while asking a model.

    The message quotes server or model text: it is clipped, key-shaped strings are redacted and
    escape sequences stripped, so it can go into a record or onto the terminal as it is.
    ``retryable`` says whether an episode that ended in it is worth running again (a transient
    cause: ``eval --resume --retry-errors`` re-runs it; ``run`` exits 75).
    """

    retryable = False

    def __init__(self, message: str = "") -> None:
        super().__init__(clip(for_terminal(message), MAX_ERROR_CHARS))


class LLMTransportError(LLMError):
    """The request did not produce an answer; ``attempts`` says how many tries were made."""

    retryable = True

    def __init__(self, message: str, *, attempts: int = 1) -> None:
        super().__init__(message)
        self.attempts = attempts


class LLMTimeout(LLMTransportError):
    """The server did not answer within the configured timeout (after all retries)."""


class LLMConnectionError(LLMTransportError):
    """The server could not be reached or dropped the connection (after all retries)."""


class LLMStatusError(LLMTransportError):
    """The server answered with an HTTP error status."""

    def __init__(self, message: str, *, status_code: int, attempts: int = 1) -> None:
        super().__init__(message, attempts=attempts)
        self.status_code = status_code


class LLMRateLimited(LLMStatusError):
    """HTTP 429 on every attempt."""


class LLMServerError(LLMStatusError):
    """HTTP 5xx (or another retryable status) on every attempt."""


class LLMBadRequest(LLMStatusError):
    """HTTP 4xx the server will not change its mind about (400, 404, 422, ...); never retried."""

    retryable = False


class LLMAuthError(LLMStatusError):
    """HTTP 401/403: the API key is missing, wrong or lacks access; never retried."""

    retryable = False


class LLMResponseTooLarge(LLMTransportError):
    """The response body is over ``MAX_BODY_BYTES`` (:mod:`more_agent.llm.http`); reading stopped there.

    Never retried and not retryable: no valid answer is that large, so the server is broken or
    hostile and asking again would only download it again.
    """

    retryable = False


class CacheLocked(LLMTransportError):
    """The response cache stayed locked by another process for the whole busy timeout: transient."""


class Unparseable(LLMError):
    """The answer holds no JSON object although one was asked for; ``completion`` is the answer.

    ``reason`` is what a re-ask tells the model.
    """

    reason = "no JSON object found in the answer"

    def __init__(self, message: str, *, completion: Completion) -> None:
        super().__init__(message)
        self.completion = completion


class OversizeAnswer(Unparseable):
    """The answer is longer than ``MAX_ANSWER_CHARS``: invalid, whatever it holds (recorded truncated)."""

    def __init__(self, *, completion: Completion) -> None:
        self.reason = (
            f"the answer is over the limit of {MAX_ANSWER_CHARS} characters; answer with one short JSON object"
        )
        super().__init__(self.reason, completion=completion)


class InvalidAnswer(LLMError):
    """The answer parsed but does not name a valid action / room / object; ``reason`` says why.

    ``completions`` holds the answers that led here (so their usage is still counted).
    """

    def __init__(self, reason: str, *, completions: tuple[Completion, ...] = ()) -> None:
        super().__init__(reason)
        self.reason = str(self)
        self.completions = completions


class ReplayMiss(LLMError):
    """Replay mode found no cached answer for a request: the run differs from the recorded one."""

    def __init__(self, *, key: str, model: str, purpose: str) -> None:
        what = f" for {purpose!r}" if purpose else ""
        super().__init__(
            f"replay: no cached answer{what} (model {model!r}, key {key[:16]}...); the run has diverged "
            "from the recorded one or the cache file is not the one it was recorded into"
        )
        self.key = key
        self.model = model
        self.purpose = purpose


class ContextLimitExceeded(LLMError):
    """A local model's prompt plus answer budget do not fit its context window; nothing was generated."""

    def __init__(self, message: str, *, prompt_tokens: int, n_ctx: int) -> None:
        super().__init__(message)
        self.prompt_tokens = prompt_tokens
        self.n_ctx = n_ctx


class LLMConfigError(UserError):
    """The LLM configuration cannot work: bad file, bad value, missing key."""


class BadLLMSpec(LLMConfigError):
    """An ``--llm`` value is not ``openai:MODEL`` or ``llamacpp:PATH.gguf``."""


class MissingAPIKey(LLMConfigError):
    """The official OpenAI endpoint was asked for without an API key."""


class MissingExtra(LLMConfigError):
    """An optional dependency is not installed; the message names the extra to install."""
