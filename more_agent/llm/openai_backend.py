"""Backend for any OpenAI-compatible chat-completions endpoint (OpenAI, Azure v1, vLLM, Ollama, llama.cpp).

Built on the ``openai`` SDK with its own retries switched off (``max_retries=0``): the retry loop
here retries timeouts, connection drops, 429 (honouring ``retry-after``) and 5xx with exponential
backoff and jitter, then raises the typed error of the last failure. A JSON schema is sent as
``response_format`` when structured output is on; in ``auto`` mode a rejection of that request (400,
422, or a 5xx whose error names ``response_format``, as llama-cpp-python's server sends) switches
this backend to the next way of sending it for good (:data:`SCHEMA_FORMATS`), and after the last to
plain text (the client then extracts the JSON from the text).
"""

from __future__ import annotations

import logging
import random
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from more_agent.llm import constants as C
from more_agent.llm.client import ChatRequest, Generation
from more_agent.llm.config import LLMConfig, StructuredOutput
from more_agent.llm.errors import (
    LLMAuthError,
    LLMBadRequest,
    LLMConfigError,
    LLMConnectionError,
    LLMRateLimited,
    LLMResponseTooLarge,
    LLMServerError,
    LLMTimeout,
    LLMTransportError,
    MissingAPIKey,
)
from more_agent.llm.grammar import bounded_schema
from more_agent.llm.limits import MAX_ERROR_CHARS, clip
from more_agent.llm.usage import token_count
from more_agent.redaction import has_credentials, redact, register_secret

if TYPE_CHECKING:
    import openai

log = logging.getLogger(__name__)

SCHEMA_FORMATS = ("json_schema", "json_object")
"""Ways of sending a JSON schema, tried in this order in auto mode: OpenAI's ``json_schema``, then
``{"type": "json_object", "schema": ...}``, the form llama-cpp-python's server compiles into a grammar
(it refuses the first, with HTTP 500); that schema carries the grammar's length bounds (:mod:`more_agent.llm.grammar`)."""


class _SchemaRejected(Exception):
    """The server refused the way the schema was sent; ``error`` is its answer."""

    def __init__(self, error: openai.APIStatusError) -> None:
        super().__init__(str(error))
        self.error = error


def _rejects_response_format(error: openai.APIStatusError) -> bool:
    """Whether an error status refuses the request's response_format: 400 or 422, or a 5xx that names it."""
    return error.status_code in (400, 422) or (error.status_code >= 500 and "response_format" in str(error))


def _retry_after_s(headers: Any) -> float | None:
    """Seconds a server asked us to wait (``retry-after-ms`` or ``retry-after`` in seconds), if any."""
    for name, scale in (("retry-after-ms", 1e-3), ("retry-after", 1.0)):
        value = headers.get(name) if headers is not None else None
        if value is not None:
            try:
                return max(0.0, float(value) * scale)
            except ValueError:
                continue
    return None


class OpenAIBackend:
    """Chat completions over HTTP; the SDK client is created on the first request, never at import."""

    kind = "openai"
    free = False

    def __init__(
        self,
        *,
        model: str,
        base_url: str,
        api_key: str,
        timeout_s: float = C.DEFAULT_TIMEOUT_S,
        max_retries: int = C.DEFAULT_MAX_RETRIES,
        backoff_initial_s: float = C.INITIAL_BACKOFF_S,
        backoff_max_s: float = C.MAX_BACKOFF_S,
        structured_output: StructuredOutput = StructuredOutput.AUTO,
        sleep: Callable[[float], None] = time.sleep,
        rng: random.Random | None = None,
    ) -> None:
        self.model = model
        self.base_url = base_url
        self._api_key = api_key
        self.timeout_s = timeout_s
        self.max_retries = max_retries
        self.backoff_initial_s = backoff_initial_s
        self.backoff_max_s = backoff_max_s
        self.structured_output = structured_output
        self.schema_format: str | None = None if structured_output is StructuredOutput.NEVER else SCHEMA_FORMATS[0]
        """How a schema is sent (one of SCHEMA_FORMATS); None when off or all were rejected (auto mode)."""
        self._sleep = sleep
        self._rng = rng or random.Random()
        self._sdk: openai.OpenAI | None = None

    def __repr__(self) -> str:
        return f"OpenAIBackend(model={self.model!r}, base_url={self.base_url!r})"

    @classmethod
    def from_config(cls, model: str, config: LLMConfig, *, require_key: bool = True) -> OpenAIBackend:
        """A backend for ``model`` at the configured endpoint.

        A missing key is an error only for OpenAI's own endpoint, and not at all with
        ``require_key=False`` (replay runs never send a request).
        """
        base_url = (config.base_url or C.OPENAI_BASE_URL).rstrip("/")
        if has_credentials(base_url):
            raise LLMConfigError(
                f"the base URL {redact(base_url)} must not contain credentials (they would be copied into "
                f"errors and logs); put the key in {C.ENV_API_KEY}"
            )
        key = config.api_key_value()
        register_secret(key)
        if not key:
            if require_key and base_url == C.OPENAI_BASE_URL:
                raise MissingAPIKey(
                    f"no API key for {base_url}: set {C.ENV_API_KEY} (or api_key in the LLM config), "
                    f"or point {C.ENV_BASE_URL} at a local OpenAI-compatible server"
                )
            key = C.PLACEHOLDER_API_KEY
        return cls(
            model=model,
            base_url=base_url,
            api_key=key,
            timeout_s=config.timeout_s,
            max_retries=config.max_retries,
            backoff_initial_s=config.backoff_initial_s,
            backoff_max_s=config.backoff_max_s,
            structured_output=config.structured_output,
        )

    def _client(self) -> openai.OpenAI:
        """The SDK client, built once on first use."""
        if self._sdk is None:
            import openai

            from more_agent.llm.http import bounded_client

            self._sdk = openai.OpenAI(
                api_key=self._api_key,
                base_url=self.base_url,
                timeout=self.timeout_s,
                max_retries=0,
                http_client=bounded_client(self.timeout_s),
            )
        return self._sdk

    def _backoff_s(self, retry: int, retry_after_s: float | None) -> float:
        """Sleep before retry number ``retry`` (1-based): exponential with jitter, or the server's ask."""
        base = retry_after_s if retry_after_s is not None else self.backoff_initial_s * 2 ** (retry - 1)
        return min(self.backoff_max_s, base) * (1 + C.BACKOFF_JITTER * self._rng.random())

    def _create(self, request: ChatRequest, schema_format: str | None) -> Generation:
        """One HTTP request, no retries; the schema, if any, is sent the ``schema_format`` way.

        Raises _SchemaRejected when the server refuses that way.
        """
        import openai

        extra: dict[str, Any] = {}
        if schema_format == "json_schema":
            extra["response_format"] = {
                "type": "json_schema",
                "json_schema": {"name": request.schema_name or "answer", "schema": request.schema, "strict": True},
            }
        elif schema_format == "json_object":
            extra["response_format"] = {
                "type": "json_object",
                "schema": bounded_schema(request.schema, request.max_tokens),
            }
        if request.seed is not None:
            extra["seed"] = request.seed
        try:
            resp = self._client().chat.completions.create(
                model=self.model,
                messages=list(request.messages),  # type: ignore[arg-type]
                temperature=request.temperature,
                max_tokens=request.max_tokens,
                **extra,
            )
        except openai.APIStatusError as e:
            if schema_format is not None and _rejects_response_format(e):
                raise _SchemaRejected(e) from e
            raise
        if not hasattr(resp, "choices"):
            raise LLMServerError(
                f"{self.base_url} answered with something that is not a chat completion: {str(resp)[:200]!r}",
                status_code=200,
            )
        text = (resp.choices[0].message.content or "") if resp.choices else ""
        usage = resp.usage
        return Generation(
            text=text,
            model=resp.model or self.model,
            prompt_tokens=token_count(getattr(usage, "prompt_tokens", 0)),
            completion_tokens=token_count(getattr(usage, "completion_tokens", 0)),
            attempts=1,
        )

    def generate(self, request: ChatRequest) -> Generation:
        """Answer ``request``, retrying transient failures; raises the typed error of the last one."""
        import openai

        from more_agent.llm.http import BodyTooLarge

        attempts = retries = 0
        while True:
            attempts += 1
            schema_format = self.schema_format if request.schema is not None else None
            retry_after: float | None = None
            error: LLMTransportError
            try:
                gen = self._create(request, schema_format)
                return Generation(gen.text, gen.model, gen.prompt_tokens, gen.completion_tokens, attempts)
            except _SchemaRejected as rejected:
                e = rejected.error
                if self.structured_output is StructuredOutput.AUTO:
                    later = SCHEMA_FORMATS[SCHEMA_FORMATS.index(schema_format) + 1 :]
                    self.schema_format = later[0] if later else None
                    log.warning(
                        "%s rejected response_format %s (%s); now %s",
                        self.base_url,
                        schema_format,
                        clip(str(e), MAX_ERROR_CHARS),
                        f"sending {later[0]}" if later else "parsing JSON from text",
                    )
                    continue
                raise LLMBadRequest(
                    f"{self.base_url} rejected response_format {schema_format}: {e}",
                    status_code=e.status_code,
                    attempts=attempts,
                ) from None
            except BodyTooLarge as e:
                raise LLMResponseTooLarge(f"{self.base_url}: {e}; not retried", attempts=attempts) from None
            except openai.BadRequestError as e:
                raise LLMBadRequest(
                    f"bad request to {self.model}: {e}", status_code=e.status_code, attempts=attempts
                ) from None
            except (openai.AuthenticationError, openai.PermissionDeniedError) as e:
                raise LLMAuthError(
                    f"{self.base_url} refused the API key ({e.status_code}): check {C.ENV_API_KEY}",
                    status_code=e.status_code,
                    attempts=attempts,
                ) from None
            except LLMServerError as e:
                error = LLMServerError(str(e), status_code=e.status_code, attempts=attempts)
            except openai.APIResponseValidationError as e:
                error = LLMServerError(
                    f"{self.base_url} sent an invalid chat completion: {e}",
                    status_code=e.status_code,
                    attempts=attempts,
                )
            except ValueError as e:  # the SDK's json.JSONDecodeError: a body that is not JSON at all
                error = LLMServerError(
                    f"{self.base_url} sent a body that is not JSON: {e}", status_code=200, attempts=attempts
                )
            except openai.APITimeoutError:
                error = LLMTimeout(
                    f"{self.model} at {self.base_url} did not answer within {self.timeout_s:g} s (the whole request)",
                    attempts=attempts,
                )
            except openai.APIConnectionError as e:
                error = LLMConnectionError(f"cannot reach {self.base_url}: {e}", attempts=attempts)
            except openai.APIStatusError as e:
                if e.status_code not in C.RETRYABLE_STATUS:
                    raise LLMBadRequest(
                        f"{self.base_url} answered {e.status_code}: {e}", status_code=e.status_code, attempts=attempts
                    ) from None
                kind = LLMRateLimited if e.status_code == 429 else LLMServerError
                error = kind(
                    f"{self.base_url} answered {e.status_code}: {e}", status_code=e.status_code, attempts=attempts
                )
                retry_after = _retry_after_s(e.response.headers)
            retries += 1
            if retries > self.max_retries:
                raise error
            delay = self._backoff_s(retries, retry_after)
            log.info("retry %d/%d in %.2f s after: %s", retries, self.max_retries, delay, error)
            self._sleep(delay)
