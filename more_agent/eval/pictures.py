"""Whether runs draw their pictures: ``MORE_AGENT_PICTURES=0`` leaves out each episode's ``map.png`` and a
report's comparison plots.

Matplotlib spends a few tenths of a second on each picture, longer than a short episode on a small scene
takes. A batch whose pictures nobody looks at (the test suite, a quick check of a sweep) can skip them;
records, summaries and ``report.html`` are written the same (the report then draws each episode's path as
SVG, as for an episode without a map), and a later run without the variable redraws missing maps on resume.
"""

from __future__ import annotations

import os

ENV_PICTURES = "MORE_AGENT_PICTURES"
"""Environment variable: ``0`` / ``off`` / ``false`` / ``no`` turn pictures off; unset or anything else keeps them."""


def pictures_enabled() -> bool:
    """Whether to draw ``map.png`` and the report plots (on unless ``MORE_AGENT_PICTURES`` says off)."""
    return os.environ.get(ENV_PICTURES, "").strip().lower() not in {"0", "off", "false", "no"}
