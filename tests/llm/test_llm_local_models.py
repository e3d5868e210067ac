"""Bundled GGUF models (``llamacpp:smollm2``) and the llamacpp backend's paths that need no model."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from more_agent.llm import CacheMode, LLMConfig, LLMSpec, MissingExtra, ReplayMiss, make_client, parse_llm_spec
from more_agent.llm.local_models import BUNDLED_MODELS, BundledModel, bundled_model_path, gguf_path


def test_bundled_model_names_are_specs_without_a_gguf_suffix() -> None:
    assert parse_llm_spec("llamacpp:smollm2") == LLMSpec(kind="llamacpp", model="smollm2")
    assert parse_llm_spec("llamacpp:SmolLM2").model == "SmolLM2"
    assert gguf_path("~/m.gguf") == Path.home() / "m.gguf"


def test_bundled_model_without_its_package_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    missing = BundledModel(distribution="more-agent-no-such-dist", file="x.gguf", about="")
    monkeypatch.setitem(BUNDLED_MODELS, "ghost", missing)
    with pytest.raises(MissingExtra, match=r"'more-agent-no-such-dist' package, which is not installed: .*\[local\]"):
        bundled_model_path("ghost")
    assert parse_llm_spec("llamacpp:ghost").model == "ghost"
    with pytest.raises(MissingExtra):
        gguf_path("ghost")
    # A replay never loads the model: it keys its answers by the bundled file's name, installed or not.
    assert gguf_path("ghost", require_installed=False) == Path("x.gguf")
    assert make_client("llamacpp:ghost", LLMConfig(cache_mode=CacheMode.REPLAY)).model == "x.gguf"


def test_bundled_model_file_missing_from_its_package_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(BUNDLED_MODELS, "odd", BundledModel(distribution="pytest", file="no-such.gguf", about=""))
    with pytest.raises(MissingExtra, match="pytest is installed but holds no no-such.gguf"):
        bundled_model_path("odd")


def test_replay_needs_neither_llama_cpp_nor_the_file(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setitem(sys.modules, "llama_cpp", None)  # import fails as if not installed
    config = LLMConfig(cache_path=tmp_path / "c.sqlite", cache_mode=CacheMode.REPLAY)
    client = make_client("llamacpp:/nowhere/model.gguf", config)
    assert client.model == "model.gguf"
    with pytest.raises(ReplayMiss):
        client.complete([{"role": "user", "content": "hi"}])
