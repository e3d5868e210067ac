"""Suite-wide settings: episodes and reports are written without their matplotlib pictures
(``MORE_AGENT_PICTURES=0``, set here so that ``more-agent`` subprocesses inherit it too), which cost more
than most fixture episodes; tests that look at a picture ask for ``pictures_on``. Worlds are built afresh
(``MORE_AGENT_WORLD_CACHE=off``): a test that patches how worlds are built must get the world it built, and
the suite writes nothing to the user's cache; the cache's own tests give it a file. Typer's ``CliRunner`` builds
the click command of the app it invokes once per test process, not on every call (``_command_once``). ``-n auto`` starts one
pytest-xdist worker more than the machine has cores (``pytest_xdist_auto_num_workers``)."""

from __future__ import annotations

import os
from functools import cache

import pytest
import typer.testing

from more_agent.eval.pictures import ENV_PICTURES
from more_agent.sim.world_cache import ENV_WORLD_CACHE

os.environ.setdefault(ENV_PICTURES, "0")
os.environ.setdefault(ENV_WORLD_CACHE, "off")


@cache
def _command_once(app: typer.Typer) -> object:
    """The click command of ``app``, as typer builds it: its type hints and signatures read once per process
    (30 ms a call, 4 s over the suite's ~150 CLI invocations) rather than on every ``CliRunner.invoke``."""
    return typer.main.get_command(app)


typer.testing._get_command = _command_once  # type: ignore[attr-defined]


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """One worker per core, and one more: a fifth of the suite's time is spent waiting (on local HTTP
    servers, subprocesses and signals, deadlines that must pass), time in which another test can run."""
    return (os.cpu_count() or 1) + 1


@pytest.fixture
def pictures_on(monkeypatch: pytest.MonkeyPatch) -> None:
    """Draw ``map.png`` and the report plots in this test (and the processes it starts)."""
    monkeypatch.setenv(ENV_PICTURES, "1")
