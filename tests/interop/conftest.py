"""One short episode recorded as a bag, shared by the interop tests of a session."""

from __future__ import annotations

import pytest

from tests.interop.bags import Recorded, record_episode


@pytest.fixture(scope="session")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    return record_episode(tmp_path_factory.mktemp("bag") / "episode")
