"""Suite-wide settings: episodes and reports are written without their matplotlib pictures
(``MORE_AGENT_PICTURES=0``, set here so that ``more-agent`` subprocesses inherit it too), which cost more
than most fixture episodes; tests that look at a picture ask for ``pictures_on``."""

from __future__ import annotations

import os

import pytest

from more_agent.eval.pictures import ENV_PICTURES

os.environ.setdefault(ENV_PICTURES, "0")


@pytest.fixture
def pictures_on(monkeypatch: pytest.MonkeyPatch) -> None:
    """Draw ``map.png`` and the report plots in this test (and the processes it starts)."""
    monkeypatch.setenv(ENV_PICTURES, "1")
