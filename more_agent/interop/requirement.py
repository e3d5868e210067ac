"""``require``: import an optional dependency, or fail with one line naming the extra that installs it."""

from __future__ import annotations

import importlib
from types import ModuleType

from more_agent.errors import UserError


def require(module: str, extra: str) -> ModuleType:
    """``importlib.import_module(module)``; a missing module raises a UserError naming ``extra``."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise UserError(
            f"{module} is not installed: pip install 'more-agent[{extra}]' ({type(e).__name__}: {e})"
        ) from None
