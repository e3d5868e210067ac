"""The planner protocol and registry stay light: importing them loads no simulator or planner."""

from __future__ import annotations

import subprocess
import sys


def test_importing_the_registry_loads_no_simulator() -> None:
    code = ("import sys, more_agent.planners.base; "
            "print(sorted(m for m in ('gymnasium', 'skimage', 'scipy', 'bddl', 'more_agent.sim', "
            "'more_agent.planners.oracle') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
