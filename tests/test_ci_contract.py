"""`.ci/run` keeps the README's promise: it calls the README's test command, and every marker that command
leaves out (pyproject's ``addopts``) runs in a step of its own, so CI runs every test."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _ci_commands() -> list[str]:
    return [line.strip() for line in (REPO / ".ci/run").read_text().splitlines() if line.strip().startswith("python")]


def test_ci_calls_the_readme_test_command_and_runs_every_deselected_marker() -> None:
    readme = (REPO / "README.md").read_text()
    test_command = re.search(r"Run the tests:\s*```bash\n(.+?)\n```", readme)
    assert test_command is not None, "README has no 'Run the tests:' block"
    commands = _ci_commands()
    assert test_command.group(1).strip() in commands
    pytest_ini = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    left_out = re.findall(r"not (\w+)", pytest_ini["addopts"])
    declared = {m.split(":")[0] for m in pytest_ini["markers"]}
    assert left_out and set(left_out) == declared, (left_out, declared)
    missing = [m for m in left_out if f"python -m pytest -q -m {m}" not in commands]
    assert not missing, f".ci/run never runs the tests marked {missing}"
