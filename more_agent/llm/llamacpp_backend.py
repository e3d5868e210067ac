"""In-process backend for local GGUF models through llama-cpp-python (the optional ``llamacpp`` extra).

- JSON answers are grammar-constrained: a schema goes to llama.cpp as ``response_format`` with the
  schema (bounded in length by :func:`~more_agent.llm.grammar.bounded_schema`), which
  llama-cpp-python compiles into a GBNF grammar, so the answer is JSON of that shape (unless
  ``max_tokens`` cuts it off all the same: logged as a warning).
- The chat template is the GGUF's own (``tokenizer.chat_template``), never a guessed format; a file
  without one is refused with a clear error.
- Text only: a message's images (the VLM planners' frames) are replaced by :data:`IMAGE_PLACEHOLDER`
  in its text (:func:`text_only`), with a warning once per process, since the GGUF chat templates
  take text (SmolLM2 has no vision); the model then reads the captions and object lists alone.
- The context limit is ``min(llamacpp_n_ctx, the model's training context)``. A prompt whose tokens
  plus the answer budget (``max_tokens``) exceed it raises :class:`ContextLimitExceeded` before any
  generation, instead of llama.cpp silently shortening the answer.

The model file is loaded on the first request (and kept once per process, so an evaluation that
builds a client per episode loads it once); in replay mode nothing is loaded or even imported.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from more_agent.llm.client import ChatRequest, Generation
from more_agent.llm.completion import ChatMessage
from more_agent.llm.config import LLMConfig
from more_agent.llm.errors import ContextLimitExceeded, LLMConfigError, MissingExtra
from more_agent.llm.grammar import bounded_schema

log = logging.getLogger(__name__)

INSTALL_HINT = "pip install 'more-agent[llamacpp]'"
CHAT_TEMPLATE_KEY = "tokenizer.chat_template"
"""GGUF metadata key of the model's chat template."""
GGUF_CHAT_FORMAT = "chat_template.default"
"""llama-cpp-python's name for the chat handler built from the GGUF's template."""
IMAGE_PLACEHOLDER = "[image not shown: this model reads text only]"
"""What stands in a message's text for each image it carried."""


def text_only(messages: Sequence[ChatMessage]) -> list[ChatMessage]:
    """``messages`` with every content given as parts (text and images) made one text, each image a placeholder."""
    out = []
    for m in messages:
        content = m["content"]
        if not isinstance(content, str):
            if any(part["type"] != "text" for part in content):
                _warn_images_dropped()
            content = "\n".join(p["text"] if p["type"] == "text" else IMAGE_PLACEHOLDER for p in content)
        out.append(ChatMessage(role=m["role"], content=content))
    return out


@functools.cache
def _warn_images_dropped() -> None:
    log.warning("the llama.cpp model reads text only: the images of VLM requests are left out (%s)", IMAGE_PLACEHOLDER)


def _import_llama_cpp() -> Any:
    """The llama_cpp module, or MissingExtra naming the extra to install."""
    try:
        import llama_cpp
    except ImportError:
        raise MissingExtra(f"llamacpp models need llama-cpp-python, which is not installed: {INSTALL_HINT}") from None
    return llama_cpp


def trained_context(metadata: dict[str, str]) -> int | None:
    """The context length the model was trained for, from its GGUF metadata (None if not stated)."""
    value = metadata.get(f"{metadata.get('general.architecture', '')}.context_length")
    return int(value) if value else None


def _token_text(llm: Any, token: int) -> str:
    """The text of one (special) token, e.g. ``<|im_end|>``."""
    return llm.detokenize([token], special=True).decode("utf-8", errors="replace")


@functools.lru_cache(maxsize=2)
def _load(path: Path, n_ctx: int, n_gpu_layers: int, seed: int | None, n_threads: int | None) -> Any:
    """A loaded ``llama_cpp.Llama`` using the GGUF's chat template; LLMConfigError if it has none or is no model."""
    llama_cpp = _import_llama_cpp()
    kwargs: dict[str, Any] = {"n_gpu_layers": n_gpu_layers, "verbose": False, "chat_format": GGUF_CHAT_FORMAT}
    if seed is not None:
        kwargs["seed"] = seed
    if n_threads is not None:
        kwargs["n_threads"] = kwargs["n_threads_batch"] = n_threads
    try:
        llm = llama_cpp.Llama(model_path=str(path), n_ctx=n_ctx, **kwargs)
    except ValueError as e:  # llama-cpp-python's way of saying the file is not a model it can load
        raise LLMConfigError(f"llama.cpp cannot load {path}: {e}") from None
    if CHAT_TEMPLATE_KEY not in llm.metadata:
        raise LLMConfigError(f"{path.name} holds no chat template ({CHAT_TEMPLATE_KEY}); use an instruct model's GGUF")
    trained = trained_context(llm.metadata)
    if trained is not None and trained < n_ctx:
        log.info("%s was trained for %d tokens of context: using %d, not %d", path.name, trained, trained, n_ctx)
        llm.close()
        llm = llama_cpp.Llama(model_path=str(path), n_ctx=trained, **kwargs)
    return llm


class LlamaCppBackend:
    """A GGUF model run in this process; free, so its cost is 0 and known."""

    kind = "llamacpp"
    free = True

    def __init__(
        self,
        model_path: Path,
        *,
        n_ctx: int = 8192,
        n_gpu_layers: int = 0,
        seed: int | None = None,
        n_threads: int | None = None,
        require_model: bool = True,
    ) -> None:
        """``require_model=False`` (replay runs, which never generate) skips the extra and file checks."""
        if require_model:
            _import_llama_cpp()
            if not model_path.is_file():
                raise LLMConfigError(f"GGUF model file not found: {model_path}")
        self.model_path = model_path
        self.model = model_path.name
        self._n_ctx = n_ctx
        self._n_gpu_layers = n_gpu_layers
        self._seed = seed
        self._n_threads = n_threads
        self._formatter: Any = None

    @classmethod
    def from_config(cls, model_path: Path, config: LLMConfig, *, require_model: bool = True) -> LlamaCppBackend:
        """A backend for the file, sized by the config."""
        return cls(
            model_path,
            n_ctx=config.llamacpp_n_ctx,
            n_gpu_layers=config.llamacpp_n_gpu_layers,
            seed=config.seed,
            n_threads=config.llamacpp_n_threads,
            require_model=require_model,
        )

    def llama(self) -> Any:
        """The loaded ``llama_cpp.Llama`` (loaded on first use, shared by backends of the same file and settings)."""
        return _load(self.model_path.resolve(), self._n_ctx, self._n_gpu_layers, self._seed, self._n_threads)

    @property
    def n_ctx(self) -> int:
        """The context limit in tokens: prompt plus answer budget must fit in it."""
        return int(self.llama().n_ctx())

    def prompt_tokens(self, messages: Sequence[ChatMessage]) -> int:
        """Exact tokens of ``messages`` as the model sees them: the GGUF chat template applied, then tokenized."""
        llm = self.llama()
        if self._formatter is None:
            from llama_cpp.llama_chat_format import Jinja2ChatFormatter

            self._formatter = Jinja2ChatFormatter(
                template=llm.metadata[CHAT_TEMPLATE_KEY],
                eos_token=_token_text(llm, llm.token_eos()),
                bos_token=_token_text(llm, llm.token_bos()),
            )
        rendered = self._formatter(messages=text_only(messages))
        return len(llm.tokenize(rendered.prompt.encode("utf-8"), add_bos=not rendered.added_special, special=True))

    def generate(self, request: ChatRequest) -> Generation:
        """Answer ``request`` locally; a schema constrains decoding to valid JSON of that shape.

        Raises ContextLimitExceeded when the prompt and the answer budget do not fit the context.
        """
        n_prompt, n_ctx = self.prompt_tokens(request.messages), self.n_ctx
        if n_prompt + request.max_tokens > n_ctx:
            raise ContextLimitExceeded(
                f"prompt of {n_prompt} tokens plus an answer budget of {request.max_tokens} (max_tokens) exceed the "
                f"{n_ctx}-token context of {self.model} (llamacpp_n_ctx, at most the model's training context)",
                prompt_tokens=n_prompt,
                n_ctx=n_ctx,
            )
        extra: dict[str, Any] = {}
        if request.schema is not None:
            extra["response_format"] = {
                "type": "json_object",
                "schema": bounded_schema(request.schema, request.max_tokens),
            }
        if request.seed is not None:
            extra["seed"] = request.seed
        out = self.llama().create_chat_completion(
            messages=text_only(request.messages),
            temperature=request.temperature,
            max_tokens=request.max_tokens,
            **extra,
        )
        choice = out["choices"][0]
        if choice.get("finish_reason") == "length":
            log.warning("%s stopped at max_tokens=%d: the answer is cut off", self.model, request.max_tokens)
        usage = out.get("usage") or {}
        return Generation(
            text=choice["message"].get("content") or "",
            model=self.model,
            prompt_tokens=int(usage.get("prompt_tokens", 0)),
            completion_tokens=int(usage.get("completion_tokens", 0)),
            attempts=1,
        )
