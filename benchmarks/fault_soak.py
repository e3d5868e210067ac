"""Fault soak: a whole `more-agent eval` of an LLM planner against a flaky, hostile local server,
killed with kill -9 at random and resumed, then one `--resume --retry-errors` pass.

The LLM is a cheap scripted one (the local OpenAI-compatible server of tests/fakes labels rooms,
filters nothing and calls done()), so an episode costs about a second of simulation; a share of
its answers are faults of every kind in tests/fakes/faults.py (oversize, garbage, 500 bursts,
429 with an hour's Retry-After, resets, timeouts, prompt injection, rich markup). Prints one JSON
object: episodes run, faults injected by kind, kills, duplicates (must be 0), lost episodes (0),
retryable errors left after one --retry-errors pass (0 expected), peak cache size, wall time.

    python benchmarks/fault_soak.py --episodes 200 --workers 2 --fault-rate 0.05 --kills 2

With ``--cases`` it runs the hostile cases of ``benchmarks/hostile_cases.py`` instead (trickling and
flooding servers, folders that lie, numbers that cannot be, signals), one CLI subprocess each, and
prints a Markdown table of cases x outcome (traceback / wrong exit / data / secret / terminal) and
one JSON line of the counts. ``--python`` and ``--repo`` measure another checkout's code, e.g.
main's, read-only (its folders are only read; every case writes under a temporary folder)::

    python benchmarks/fault_soak.py --cases
    python benchmarks/fault_soak.py --cases --python /work/main/.venv/bin/python --repo /work/main
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from more_agent.eval.store import read_records  # noqa: E402
from tests.fakes.faults import FaultyResponder  # noqa: E402
from tests.fakes.openai_server import FakeOpenAIServer  # noqa: E402
from tests.test_cli_faults import KITCHEN, TASK, quick_brain  # noqa: E402

# The cache is written but never read (mode refresh): every episode asks the server, so every
# episode meets the faults, while the cache still grows as in a real run.
LLM_CONFIG = "timeout_s = 1.0\nmax_retries = 2\nbackoff_initial_s = 0.05\nbackoff_max_s = 0.2\n"
"""Short timeout and backoff: a Retry-After of an hour is capped at 0.2 s, a slow answer times out in 1 s."""


def eval_command(out: Path, episodes: int, workers: int, *extra: str) -> list[str]:
    """The `more-agent eval` command line of the soak."""
    return [sys.executable, "-c", "from more_agent.cli import app; app(prog_name='more-agent')", "eval", "--tasks", TASK, "--scene", str(KITCHEN), "--seeds",
            str(episodes), "--planner", "more", "--llm", "openai:soak-model", "--workers", str(workers),
            "--out", str(out), "--no-progress", *extra]


class CacheWatch:
    """Samples the size of the sqlite cache (with its WAL) every 0.2 s; ``peak`` is the largest seen."""

    def __init__(self, path: Path) -> None:
        self.path, self.peak = path, 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.2):
            self.sample()

    def sample(self) -> None:
        size = sum(p.stat().st_size for p in self.path.parent.glob(self.path.name + "*") if p.is_file())
        self.peak = max(self.peak, size)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()
        self.sample()


def run_killed(cmd: list[str], env: dict[str, str], jsonl: Path, kill_at: int | None) -> int | None:
    """Run ``cmd``; with ``kill_at``, kill -9 its whole process group once ``jsonl`` holds that many lines."""
    proc = subprocess.Popen(cmd, cwd=REPO, env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if kill_at is None:
        _, err = proc.communicate()
        if proc.returncode not in (0, 75):
            print(err, file=sys.stderr)
        return proc.returncode
    while proc.poll() is None:
        if jsonl.exists() and jsonl.read_bytes().count(b"\n") >= kill_at:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return None
        time.sleep(0.05)
    return proc.returncode


def hostile_cases(python: str, repo: Path, only: str | None) -> None:
    """Run the hostile cases against ``repo``'s code; print the table and the counts."""
    from benchmarks.hostile_cases import CASES, COLUMNS, run_case, table

    results = []
    for case in CASES:
        if only and only not in case.name:
            continue
        result = run_case(case, python=python, repo=repo, kitchen=KITCHEN)
        print(json.dumps({k: v for k, v in result.items()}, default=str), file=sys.stderr, flush=True)
        results.append(result)
    print(table(results))
    print(json.dumps({"benchmark": "fault_soak_cases", "repo": str(repo), "cases": len(results),
                      "failed_cases": sum(any(r[c] for c in COLUMNS) for r in results),
                      **{c: sum(bool(r[c]) for r in results) for c in COLUMNS}}), flush=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", action="store_true", help="run the hostile cases and print their table instead")
    p.add_argument("--python", default=sys.executable, help="with --cases: the interpreter to run the CLI with")
    p.add_argument("--repo", type=Path, default=REPO, help="with --cases: the checkout whose code runs")
    p.add_argument("--only", help="with --cases: only the cases whose name holds this text")
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--fault-rate", type=float, default=0.05, help="share of LLM requests that start a fault")
    p.add_argument("--kills", type=int, default=2, help="kill -9 the eval this many times at random progress")
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    if a.cases:
        hostile_cases(a.python, a.repo.resolve(), a.only)
        return
    rng = random.Random(a.seed)
    responder = FaultyResponder(quick_brain, rate=a.fault_rate, seed=a.seed, slow_s=1.5, oversize_chars=5_000_000)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as d, FakeOpenAIServer(responder=responder) as server:
        root = Path(d)
        (root / "llm.toml").write_text(LLM_CONFIG)
        cache = root / "cache.sqlite"
        env = {**os.environ, "PYTHONPATH": str(REPO), "OPENAI_BASE_URL": server.base_url,
               "OPENAI_API_KEY": "sk-soak-0123456789abcdef", "MORE_AGENT_LLM_CONFIG": str(root / "llm.toml"),
               "MORE_AGENT_LLM_CACHE": str(cache), "MORE_AGENT_LLM_CACHE_MODE": "refresh"}
        env.pop("MORE_AGENT_LLM", None)
        out, jsonl = root / "run", root / "run" / "episodes.jsonl"
        watch = CacheWatch(cache)
        kills = 0
        for k in range(a.kills):
            done = jsonl.read_bytes().count(b"\n") if jsonl.exists() else 0
            target = done + rng.randint(1, max(1, (a.episodes - done) // (a.kills - k + 1)))
            resume = ("--resume",) if jsonl.exists() or out.exists() else ()
            if run_killed(eval_command(out, a.episodes, a.workers, *resume), env, jsonl, target) is None:
                kills += 1
        status = run_killed(eval_command(out, a.episodes, a.workers, "--resume"), env, jsonl, None)
        left_before = sum(r.retryable for r in read_records(out))
        retry_status = run_killed(eval_command(out, a.episodes, a.workers, "--resume", "--retry-errors"), env, jsonl,
                                  None)
        watch.stop()
        records = read_records(out)
        keys = Counter(r.key() for r in records)
        expected = {(TASK, "tasks_kitchen", s, "more") for s in range(a.episodes)}
        print(json.dumps({
            "benchmark": "fault_soak",
            "episodes": a.episodes,
            "workers": a.workers,
            "fault_rate": a.fault_rate,
            "llm_requests": len(server.requests),
            "faults_injected": sum(responder.injected.values()),
            "faults_by_kind": dict(sorted(responder.injected.items())),
            "kills": kills,
            "episodes_recorded": len(records),
            "duplicates": sum(n - 1 for n in keys.values()),
            "lost": len(expected - set(keys)),
            "retryable_before_retry_pass": left_before,
            "retryable_left_after_retry_pass": sum(r.retryable for r in records),
            "other_errors": sum(r.error is not None and not r.retryable for r in records),
            "exit_status_before_retry": status,
            "exit_status_after_retry": retry_status,
            "peak_cache_bytes": watch.peak,
            "seconds": round(time.perf_counter() - start, 1),
        }), flush=True)


if __name__ == "__main__":
    main()
