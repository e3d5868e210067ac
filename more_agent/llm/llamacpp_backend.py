"""In-process backend for local GGUF models through llama-cpp-python (the optional ``llamacpp`` extra).

JSON answers are grammar-constrained: a schema goes to llama.cpp as ``response_format`` with the
schema, which llama-cpp-python compiles into a grammar. The model file is loaded on the first
request, so building a client (e.g. for replay) stays cheap.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from more_agent.llm.client import ChatRequest, Generation
from more_agent.llm.config import LLMConfig
from more_agent.llm.errors import LLMConfigError, MissingExtra

INSTALL_HINT = "pip install 'more-agent[llamacpp]'"


def _import_llama_cpp() -> Any:
    """The llama_cpp module, or MissingExtra naming the extra to install."""
    try:
        import llama_cpp
    except ImportError:
        raise MissingExtra(f"llamacpp models need llama-cpp-python, which is not installed: {INSTALL_HINT}") from None
    return llama_cpp


class LlamaCppBackend:
    """A GGUF model run in this process; free, so its cost is 0 and known."""

    kind = "llamacpp"
    free = True

    def __init__(self, model_path: Path, *, n_ctx: int = 8192, n_gpu_layers: int = 0, seed: int | None = None) -> None:
        self._llama_cpp = _import_llama_cpp()
        if not model_path.is_file():
            raise LLMConfigError(f"GGUF model file not found: {model_path}")
        self.model_path = model_path
        self.model = model_path.name
        self._n_ctx = n_ctx
        self._n_gpu_layers = n_gpu_layers
        self._seed = seed
        self._llm: Any = None

    @classmethod
    def from_config(cls, model_path: Path, config: LLMConfig) -> LlamaCppBackend:
        """A backend for the file, sized by the config."""
        return cls(model_path, n_ctx=config.llamacpp_n_ctx, n_gpu_layers=config.llamacpp_n_gpu_layers, seed=config.seed)

    def _model(self) -> Any:
        """The loaded model (loaded once, on first use)."""
        if self._llm is None:
            kwargs: dict[str, Any] = {"n_ctx": self._n_ctx, "n_gpu_layers": self._n_gpu_layers, "verbose": False}
            if self._seed is not None:
                kwargs["seed"] = self._seed
            self._llm = self._llama_cpp.Llama(model_path=str(self.model_path), **kwargs)
        return self._llm

    def generate(self, request: ChatRequest) -> Generation:
        """Answer ``request`` locally; a schema constrains decoding to valid JSON of that shape."""
        extra: dict[str, Any] = {}
        if request.schema is not None:
            extra["response_format"] = {"type": "json_object", "schema": request.schema}
        out = self._model().create_chat_completion(
            messages=list(request.messages),
            temperature=request.temperature,
            max_tokens=request.max_tokens,
            **extra,
        )
        usage = out.get("usage") or {}
        return Generation(
            text=out["choices"][0]["message"].get("content") or "",
            model=self.model,
            prompt_tokens=int(usage.get("prompt_tokens", 0)),
            completion_tokens=int(usage.get("completion_tokens", 0)),
            attempts=1,
        )
