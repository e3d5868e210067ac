"""LLM specs, config loading from file and environment, client construction errors."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from pydantic import ValidationError

from more_agent.errors import UserError
from more_agent.llm import (
    BadLLMSpec,
    CacheMode,
    LLMConfig,
    LLMConfigError,
    LLMSpec,
    MissingAPIKey,
    MissingExtra,
    configured_llm,
    llm_configured,
    load_llm_config,
    make_client,
    parse_llm_spec,
    room_spec,
)


def test_parse_good_specs() -> None:
    assert parse_llm_spec("openai:gpt-4o") == LLMSpec(kind="openai", model="gpt-4o")
    assert parse_llm_spec(" OpenAI:Qwen/Qwen2.5-7B-Instruct ").model == "Qwen/Qwen2.5-7B-Instruct"
    spec = parse_llm_spec("llamacpp:/models/qwen:7b.gguf")
    assert spec == LLMSpec(kind="llamacpp", model="/models/qwen:7b.gguf") and str(spec) == "llamacpp:/models/qwen:7b.gguf"


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("gpt-4o", "no backend prefix"),
        ("opnai:gpt-4o", "did you mean 'openai'"),
        ("ollama:llama3", "unknown LLM backend 'ollama'"),
        ("openai:", "names no model"),
        ("llamacpp:model.bin", "not a .gguf file"),
    ],
)
def test_bad_specs_are_user_errors(spec: str, message: str) -> None:
    with pytest.raises(BadLLMSpec, match=message) as info:
        parse_llm_spec(spec)
    assert isinstance(info.value, UserError) and "openai:MODEL" in str(info.value)


def test_missing_llamacpp_extra_names_the_extra(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setitem(sys.modules, "llama_cpp", None)  # import fails as if not installed
    with pytest.raises(MissingExtra, match=r"pip install 'more-agent\[llamacpp\]'"):
        make_client("llamacpp:model.gguf", LLMConfig(cache_path=tmp_path / "c.sqlite"))


def test_api_key_needed_only_for_openais_endpoint(tmp_path: Path) -> None:
    with pytest.raises(MissingAPIKey, match="OPENAI_API_KEY"):
        make_client("openai:gpt-4o", LLMConfig(cache_path=tmp_path / "c.sqlite"))
    local = make_client("openai:llama3", LLMConfig(base_url="http://127.0.0.1:11434/v1", cache_path=tmp_path / "c.sqlite"))
    assert local.model == "llama3"


def test_config_from_toml_then_environment(tmp_path: Path) -> None:
    path = tmp_path / "exp.toml"
    path.write_text(
        '[llm]\nllm = "openai:gpt-4o"\nroom_model = "gpt-3.5-turbo"\ntemperature = 0.2\n'
        'base_url = "http://file/v1"\n[llm.prices.my-model]\ninput_per_m = 1.0\noutput_per_m = 2.0\n'
    )
    env = {"OPENAI_BASE_URL": "http://env/v1", "OPENAI_API_KEY": "sk-env", "MORE_AGENT_LLM_CACHE_MODE": "replay"}
    config = load_llm_config(path, env=env)
    assert config.llm == "openai:gpt-4o" and config.temperature == 0.2 and config.room_model == "gpt-3.5-turbo"
    assert config.base_url == "http://env/v1" and config.api_key_value() == "sk-env"
    assert config.cache_mode is CacheMode.REPLAY and config.prices["my-model"].output_per_m == 2.0
    assert "sk-env" not in repr(config)
    with pytest.raises(ValidationError):
        config.temperature = 1.0  # type: ignore[misc]


def test_config_file_from_environment_json_and_overrides(tmp_path: Path) -> None:
    path = tmp_path / "llm.json"
    path.write_text(json.dumps({"timeout_s": 5, "max_retries": 1}))
    config = load_llm_config(env={"MORE_AGENT_LLM_CONFIG": str(path)}, overrides={"max_retries": 0})
    assert (config.timeout_s, config.max_retries) == (5, 0)


@pytest.mark.parametrize(
    ("content", "message"),
    [("temperature = 7\n", "temperature"), ("colour = 1\n", "colour"), ("temperature = [\n", "cannot parse")],
)
def test_bad_config_files(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(content)
    with pytest.raises(LLMConfigError, match=message):
        load_llm_config(path, env={})
    with pytest.raises(LLMConfigError, match="cannot read"):
        load_llm_config(tmp_path / "missing.toml", env={})


def test_which_llm_is_configured() -> None:
    none = load_llm_config(env={})
    assert configured_llm(none) is None and not llm_configured(none)
    from_env = load_llm_config(env={"MORE_AGENT_LLM": "openai:gpt-4o"})
    assert llm_configured(from_env) and configured_llm(from_env) == LLMSpec(kind="openai", model="gpt-4o")
    assert configured_llm(from_env, "llamacpp:m.gguf") == LLMSpec(kind="llamacpp", model="m.gguf")
    with pytest.raises(BadLLMSpec):
        configured_llm(load_llm_config(env={"MORE_AGENT_LLM": "gpt-4o"}))


def test_room_classification_model() -> None:
    spec = LLMSpec(kind="openai", model="gpt-4o")
    assert room_spec(spec, LLMConfig(room_model="gpt-3.5-turbo")) == LLMSpec(kind="openai", model="gpt-3.5-turbo")
    assert room_spec(spec, LLMConfig()) == spec
    local = LLMSpec(kind="llamacpp", model="m.gguf")
    assert room_spec(local, LLMConfig(room_model="gpt-3.5-turbo")) == local
    # a full spec picks its own backend; an Ollama-style name with a colon stays a model name
    assert room_spec(local, LLMConfig(room_model="openai:gpt-3.5-turbo")) == LLMSpec(kind="openai", model="gpt-3.5-turbo")
    assert room_spec(spec, LLMConfig(room_model="llamacpp:smollm2")) == LLMSpec(kind="llamacpp", model="smollm2")
    assert room_spec(spec, LLMConfig(room_model="llama3:8b")) == LLMSpec(kind="openai", model="llama3:8b")
