"""Key-shaped strings are masked wherever they would be written or printed."""

from __future__ import annotations

import pytest

from more_agent.redaction import has_credentials, redact, register_secret


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("openai:gpt-4o?api_key=sk-123&base=x", "openai:gpt-4o?api_key=***&base=x"),
        ("cannot reach http://user:sk-abcdef123456@host:8000/v1: refused", "cannot reach http://***@host:8000/v1: refused"),
        ("Authorization: Bearer abcdefghijklmnop", "Authorization: Bearer ***"),
        ("the key is sk-proj-ABCdef0123456789xyz.", "the key is ***."),
        ("token=hf_abcdefghijklmnopqrstu", "token=***"),
        ("desk-lamp_12345678 and task-board", "desk-lamp_12345678 and task-board"),
    ],
)
def test_redact_masks_key_shapes_and_keeps_ordinary_names(text: str, expected: str) -> None:
    assert redact(text) == expected
    assert has_credentials(text) is (text != expected)


def test_a_registered_key_is_masked_anywhere() -> None:
    register_secret("plain-looking-secret-42")
    assert redact("echo plain-looking-secret-42!") == "echo ***!"
    register_secret("abc")  # too short to search for
    assert redact("abc") == "abc"
