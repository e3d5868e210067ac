"""The client protocol the planners use, and the one implementation: backend + cache + replay + meter.

A *backend* (OpenAI-compatible HTTP, in-process llama.cpp) turns a :class:`ChatRequest` into a
:class:`Generation` and knows nothing of caching; :class:`ChatClient` adds the sqlite cache, replay,
JSON extraction, cost and usage accounting on top of any backend.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from pydantic import BaseModel

from more_agent.llm.cache import CachedAnswer, ResponseCache, request_key
from more_agent.llm.completion import ChatMessage, Completion, TokenUsage
from more_agent.llm.concurrency import LLMConcurrencyLimiter, llm_limiter
from more_agent.llm.config import CacheMode, ModelPrice
from more_agent.llm.errors import OversizeAnswer, ReplayMiss, Unparseable
from more_agent.llm.images import cache_view, image_stats
from more_agent.llm.jsontext import extract_json, json_schema_of
from more_agent.llm.limits import MAX_ANSWER_CHARS, clip
from more_agent.llm.usage import UsageMeter, cost_usd, price_of
from more_agent.redaction import redact

log = logging.getLogger(__name__)


class LLMClient(Protocol):
    """What planners call. ``schema`` asks for a JSON answer of that shape (parsed into ``parsed``)."""

    @property
    def model(self) -> str:
        """Model name as sent to the server (or the GGUF file name)."""
        ...

    def complete(
        self,
        messages: Sequence[ChatMessage],
        *,
        schema: type[BaseModel] | None = None,
        purpose: str = "",
        attempt: int = 0,
    ) -> Completion:
        """One answer to ``messages``. Raises an LLMError subclass (Unparseable if JSON was asked and none came)."""
        ...


@dataclass(frozen=True)
class ChatRequest:
    """One request as a backend sees it."""

    messages: tuple[ChatMessage, ...]
    schema: dict[str, Any] | None
    """JSON schema the answer must follow, or None for free text."""
    schema_name: str
    temperature: float
    max_tokens: int
    seed: int | None


@dataclass(frozen=True)
class Generation:
    """A backend's raw answer."""

    text: str
    model: str
    prompt_tokens: int
    completion_tokens: int
    attempts: int


class Backend(Protocol):
    """Something that generates answers: an HTTP endpoint or an in-process model."""

    kind: str
    """Backend family ('openai', 'llamacpp'); part of the cache key."""
    model: str
    free: bool
    """True for local models: cost is known to be 0."""

    def generate(self, request: ChatRequest) -> Generation:
        """Answer ``request`` (retries included); raises LLMTransportError subclasses."""
        ...


class ChatClient:
    """:class:`LLMClient` over a backend with cache, replay and usage metering.

    ``usage`` sums every call of this client; planners that need per-episode numbers make one client
    per episode or add each returned Completion to their own :class:`UsageMeter`.
    """

    def __init__(
        self,
        backend: Backend,
        *,
        cache: ResponseCache | None,
        cache_mode: CacheMode = CacheMode.ON,
        temperature: float = 0.0,
        max_tokens: int = 1024,
        seed: int | None = None,
        prices: Mapping[str, ModelPrice] | None = None,
        limiter: LLMConcurrencyLimiter | None = None,
        name_enums: bool = False,
    ) -> None:
        if cache is None and cache_mode in (CacheMode.ON, CacheMode.REFRESH, CacheMode.REPLAY):
            raise ValueError(f"cache mode {cache_mode.value!r} needs a cache")
        self.backend = backend
        self.cache = cache
        self.cache_mode = cache_mode
        self.temperature = temperature
        self.max_tokens = max_tokens
        self.seed = seed
        self.prices = dict(prices or {})
        self.usage = UsageMeter()
        self.name_enums = name_enums
        """Whether planners send answer schemas that enumerate the valid names (:mod:`more_agent.llm.name_enums`)."""
        self.limiter = limiter or llm_limiter()
        """Held around each request: one cap on concurrent calls across evaluation workers (default:
        the limiter the harness installed in this worker process)."""

    @property
    def model(self) -> str:
        return self.backend.model

    def complete(
        self,
        messages: Sequence[ChatMessage],
        *,
        schema: type[BaseModel] | None = None,
        purpose: str = "",
        attempt: int = 0,
    ) -> Completion:
        """One answer; ``attempt`` separates repeated asks of the same prompt in the cache."""
        request = ChatRequest(
            messages=tuple(ChatMessage(role=m["role"], content=m["content"]) for m in messages),
            schema=json_schema_of(schema) if schema is not None else None,
            schema_name=schema.__name__ if schema is not None else "",
            temperature=self.temperature,
            max_tokens=self.max_tokens,
            seed=self.seed,
        )
        key_fields = {
            "backend": self.backend.kind,
            "model": self.backend.model,
            "messages": [cache_view(m) for m in request.messages],  # images by the hash of their bytes
            "schema": request.schema,
            "temperature": request.temperature,
            "max_tokens": request.max_tokens,
            "seed": request.seed,
            "attempt": attempt,
        }
        key = request_key(key_fields)
        start = time.perf_counter()
        reads = self.cache_mode in (CacheMode.ON, CacheMode.REPLAY)
        hit = self.cache.get(key) if reads and self.cache is not None else None
        if hit is None and self.cache_mode is CacheMode.REPLAY:
            raise ReplayMiss(key=key, model=self.backend.model, purpose=purpose)
        if hit is not None:
            answer, attempts = hit, 0
        else:
            with self.limiter:
                gen = self.backend.generate(request)
            # Clipped (an oversize answer is stored truncated) and redacted (a server echoing a key).
            answer = CachedAnswer(
                redact(clip(gen.text, MAX_ANSWER_CHARS)), redact(gen.model), gen.prompt_tokens, gen.completion_tokens
            )
            attempts = gen.attempts
            if self.cache is not None and self.cache_mode in (CacheMode.ON, CacheMode.REFRESH):
                self.cache.put(key, request=key_fields, purpose=purpose, answer=answer)
        completion = self._completion(
            answer,
            request,
            cached=hit is not None,
            attempts=attempts,
            purpose=purpose,
            latency_s=time.perf_counter() - start,
        )
        completion = dataclasses.replace(completion, **dataclasses.asdict(image_stats(request.messages)))
        self.usage.add(completion)
        if len(completion.text) > MAX_ANSWER_CHARS:  # stored and returned clipped, and invalid whatever it holds
            raise OversizeAnswer(completion=completion)
        log.debug(
            "llm %s model=%s tokens=%d+%d cost=%.5f cached=%s latency=%.2fs attempts=%d",
            purpose or "call",
            completion.model,
            completion.usage.prompt_tokens,
            completion.usage.completion_tokens,
            completion.cost_usd,
            completion.cached,
            completion.latency_s,
            completion.attempts,
        )
        if request.schema is not None and completion.parsed is None:
            raise Unparseable(
                f"no JSON object in the answer to {purpose or 'a request'}: {answer.text[:200]!r}",
                completion=completion,
            )
        return completion

    def _completion(
        self,
        answer: CachedAnswer,
        request: ChatRequest,
        *,
        cached: bool,
        attempts: int,
        purpose: str,
        latency_s: float,
    ) -> Completion:
        """The Completion for an answer (clipped when it was generated, so cached ones are too): JSON
        extracted if asked for and not clipped, cost from the price table."""
        if self.backend.free:
            cost, known = 0.0, True
        else:
            price = price_of(answer.model, self.prices) or price_of(self.backend.model, self.prices)
            known = price is not None
            cost = 0.0 if cached or price is None else cost_usd(price, answer.prompt_tokens, answer.completion_tokens)
        text = answer.text
        return Completion(
            text=text,
            parsed=extract_json(text) if request.schema is not None and len(text) <= MAX_ANSWER_CHARS else None,
            model=answer.model,
            usage=TokenUsage(answer.prompt_tokens, answer.completion_tokens),
            cost_usd=cost,
            cost_known=known,
            cached=cached,
            latency_s=latency_s,
            attempts=attempts,
            purpose=purpose,
        )
