"""Images through the LLM client: sent as base64 PNG parts, counted, cached by the hash of their bytes."""

from __future__ import annotations

import io
import json
import sqlite3

import numpy as np
import pytest
from PIL import Image

from more_agent.llm import LLMConfig, make_client
from more_agent.llm.completion import ChatMessage
from more_agent.llm.images import image_part, image_tokens, png_bytes, png_size, text_part
from tests.fakes.openai_server import FakeOpenAIServer, request_images


def _frame(value: int) -> bytes:
    rgb = np.zeros((256, 256, 3), dtype=np.uint8)
    rgb[64:128, 32:96] = value
    return png_bytes(rgb)


def _messages(png: bytes) -> list[ChatMessage]:
    return [ChatMessage(role="user", content=[text_part("What is in the frame?"), image_part(png)])]


@pytest.mark.parametrize(("size", "detail", "tokens"), [
    ((256, 256), "low", 85), ((256, 256), "high", 255), ((1024, 1024), "high", 765), ((2048, 4096), "high", 1105),
])
def test_openai_image_token_rule(size: tuple[int, int], detail: str, tokens: int) -> None:
    assert image_tokens(*size, detail) == tokens  # type: ignore[arg-type]


def test_image_reaches_the_server_decodable_and_is_counted(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    png = _frame(200)
    fake_openai.push("a grey square")
    out = make_client("openai:gpt-4o", llm_config).complete(_messages(png))
    (sent,) = request_images(fake_openai.requests[0].body)
    assert sent == png and png_size(sent) == (256, 256)
    assert np.asarray(Image.open(io.BytesIO(sent)))[100, 50].tolist() == [200, 200, 200]
    assert (out.images, out.image_bytes, out.image_tokens) == (1, len(png), 85)
    assert out.cost_usd > 0  # priced from the server's prompt tokens, which include the image's


def test_cache_key_covers_the_image_bytes_and_replay_works(fake_openai: FakeOpenAIServer, llm_config: LLMConfig) -> None:
    fake_openai.push("first", "second")
    client = make_client("openai:gpt-4o", llm_config)
    a = client.complete(_messages(_frame(10)))
    b = client.complete(_messages(_frame(11)))  # same text, other pixels: a new request
    again = client.complete(_messages(_frame(10)))
    assert (a.text, b.text, again.text) == ("first", "second", "first")
    assert len(fake_openai.requests) == 2 and again.cached and again.images == 1
    replay = make_client("openai:gpt-4o", llm_config.model_copy(update={"cache_mode": "replay", "base_url": "http://127.0.0.1:9/v1"}))
    assert replay.complete(_messages(_frame(11))).text == "second"
    stored = sqlite3.connect(llm_config.cache_path).execute("SELECT request FROM responses").fetchall()
    for (request,) in stored:
        assert "base64" not in request and "sha256:" in json.loads(request)["messages"][0]["content"][1]["image_url"]["url"]


def test_llamacpp_requests_carry_text_with_a_placeholder_per_image() -> None:
    """GGUF chat templates take text: a VLM request reaches llama.cpp as its text, each image marked as left out."""
    from more_agent.llm.llamacpp_backend import IMAGE_PLACEHOLDER, text_only

    png = png_bytes(np.zeros((4, 4, 3), dtype=np.uint8))
    messages = [ChatMessage(role="system", content="You see."),
                ChatMessage(role="user", content=[text_part("Current view:"), image_part(png), text_part("1: fridge A")])]
    system, user = text_only(messages)
    assert system == messages[0] and user == {"role": "user", "content": f"Current view:\n{IMAGE_PLACEHOLDER}\n1: fridge A"}
