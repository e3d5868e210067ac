"""CPU seconds per test: a pytest plugin for finding where the suite's time goes on a loaded machine.

Wall times of a shared machine mostly measure the load; this records each test's CPU time (its own
process plus the children it waited for, e.g. ``more-agent`` subprocesses) beside its wall time, one
JSON line per test, and prints the slowest by CPU at the end. Workers of pytest-xdist append to the same
file, so it also works with ``-n 2``.

    python -m pytest -q -n 0 -p benchmarks.cpu_per_test            # writes cpu_per_test.jsonl
    TEST_CPU_OUT=/tmp/cpu.jsonl python -m pytest -q -p benchmarks.cpu_per_test
"""

from __future__ import annotations

import json
import os
import resource
import time
from collections.abc import Generator
from pathlib import Path

import pytest

OUT = Path(os.environ.get("TEST_CPU_OUT", "cpu_per_test.jsonl"))


def _cpu() -> tuple[float, float]:
    """(own, waited children) user + system seconds so far."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime


def pytest_sessionstart(session: pytest.Session) -> None:
    if not os.environ.get("PYTEST_XDIST_WORKER"):  # the controller (or the only process) starts the file afresh
        OUT.unlink(missing_ok=True)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Generator[None, None, None]:
    (own0, children0), wall0 = _cpu(), time.perf_counter()
    yield
    (own1, children1), wall1 = _cpu(), time.perf_counter()
    line = {"id": item.nodeid, "own": own1 - own0, "children": children1 - children0, "wall": wall1 - wall0}
    with OUT.open("a", encoding="utf-8") as f:
        f.write(json.dumps(line) + "\n")


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    if not OUT.exists() or os.environ.get("PYTEST_XDIST_WORKER"):
        return
    rows = [json.loads(line) for line in OUT.read_text(encoding="utf-8").splitlines()]
    rows.sort(key=lambda r: -(r["own"] + r["children"]))
    total = sum(r["own"] + r["children"] for r in rows)
    terminalreporter.write_sep("=", f"CPU per test ({OUT}: {len(rows)} lines, {total:.1f} s in all)")
    for r in rows[:15]:
        terminalreporter.write_line(f"{r['own'] + r['children']:6.2f}s cpu {r['wall']:6.2f}s wall  {r['id']}")
