"""A missing optional dependency is one error naming the extra that installs it."""

from __future__ import annotations

import pytest

from more_agent.errors import UserError
from more_agent.interop.requirement import require


def test_a_missing_module_names_its_extra():
    with pytest.raises(UserError, match=r"no_such_module_for_more is not installed: pip install 'more-agent\[ros\]'"):
        require("no_such_module_for_more", "ros")
    assert require("json", "none").dumps([1]) == "[1]"
