"""Hostile cases for ``benchmarks/fault_soak.py --cases``: servers that trickle or flood, folders that
lie, numbers that cannot be, signals (issue 23's probe, grown).

Each case runs the real ``more-agent`` CLI in a subprocess (any checkout: ``--python`` and ``--repo``
name the interpreter and the code, so main's code can be measured read-only), in a fresh folder,
against its own local OpenAI-compatible server when it needs one, and is judged on five counts:

- traceback: "Traceback" or "Exception ignored" in its output;
- wrong exit: an exit status other than the contract's (docs/evaluation.md, "Exit status"), or
  killed after its time limit;
- data: something already written lost, two episodes mixed, or a number that cannot be;
- secret: the API key in any file under the case's folder or in the output;
- terminal: an escape sequence from a server or a scene name reached the output.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import resource
import signal
import sqlite3
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from tests.fakes.openai_server import FakeOpenAIServer, Huge, Reply, ScriptItem, Status, Trickle

KEY = "sk-hostile-DO-NOT-LEAK-0123456789"
KITCHEN = Path(__file__).resolve().parents[1] / "tests" / "fixtures" / "tasks_kitchen_scene.json"
TASK = "putting_shopping_away"
COLUMNS = ("traceback", "wrong exit", "data", "secret", "terminal")

Check = Callable[[Path, str], str | None]
"""(case folder, output) -> what is wrong with the data, or None."""


@dataclass
class Case:
    """One hostile case: CLI arguments ({d}: the case folder, {k}: the kitchen scene), the exit status
    the contract asks for, and what to set up and check."""

    name: str
    args: list[str]
    expect: int
    script: list[ScriptItem] | None = None
    """Answers of the case's server (None: no server; the brain answers once they are used up)."""
    env: dict[str, str] = field(default_factory=dict)
    setup: Callable[[Path], None] | None = None
    check: Check | None = None
    signal_after_s: tuple[int, float] | None = None
    """(signal, seconds): send it to the command that long after it started."""
    limit_s: float = 60.0
    limits: dict[int, int] = field(default_factory=dict)
    """resource.RLIMIT_* -> soft and hard limit of the command (memory, file size)."""
    held_lock: str | None = None
    """A path (relative to the case folder) whose flock the harness holds while the command runs."""
    held_cache: bool = False
    """Hold an exclusive sqlite lock on the cache while the command runs."""
    tmpfs_kb: int | None = None
    """Mount a tmpfs of this size at {d}/ep (a disk that fills up; needs root)."""


def brain(body: dict) -> str:
    """Labels every room a kitchen, keeps nothing in the filter, then calls done() (a short episode)."""
    if "Possible room types" in str(body["messages"][-1]["content"]):
        return json.dumps({"room": "kitchen"})
    if "Remove every object" in str(body["messages"][0]["content"]):
        return json.dumps({"rooms": []})
    return json.dumps({"reasoning": "finished", "skill": "done", "arguments": []})


# ---------------------------------------------------------------------------------------------
# Checks


def _record(d: Path, rel: str = "ep/episode.json") -> dict | None:
    try:
        return json.loads((d / rel).read_text())
    except (OSError, ValueError):
        return None


def victim_intact(d: Path, out: str) -> str | None:
    """The file a symlink pointed at still holds what it held."""
    return None if (d / "victim.txt").read_text() == "precious\n" else "the symlink's target was overwritten"


def record_written_sane(d: Path, out: str) -> str | None:
    r = _record(d)
    if r is None:
        return "no episode.json"
    u = r["llm_usage"]
    if u["cost_usd"] < 0 or u["prompt_tokens"] < 0 or u["prompt_tokens"] > 10**12:
        return f"usage that cannot be: {u['prompt_tokens']} tokens, ${u['cost_usd']}"
    return None


def no_empty_record(d: Path, out: str) -> str | None:
    p = d / "ep" / "episode.json"
    return "a 0-byte episode.json" if p.exists() and p.stat().st_size == 0 else None


def earlier_episode_kept(d: Path, out: str) -> str | None:
    r = _record(d)
    return None if r is not None and r["seed"] == 1 else "the earlier episode's record was replaced"


def no_stale_exchanges(d: Path, out: str) -> str | None:
    html = (d / "ep" / "viewer.html").read_text() if (d / "ep" / "viewer.html").exists() else ""
    return "the earlier episode's LLM exchange shows in the new viewer" if "STALE-EXCHANGE" in html else None


def _records(d: Path) -> list[dict]:
    p = d / "run" / "episodes.jsonl"
    return [json.loads(x) for x in p.read_text().splitlines() if x.strip()] if p.exists() else []


def mixed_llm_ran(d: Path, out: str) -> str | None:
    llms = sorted(str(r["llm"]) for r in _records(d))
    run = json.loads((d / "run" / "run.json").read_text())
    if llms != ["openai:a", "openai:b"]:
        return f"records of {llms}, not of both LLMs"
    if not any(e.get("llm") == "openai:a" for e in run.get("earlier", [])):
        return "run.json claims only the new LLM"
    return None


def task_without_bom(d: Path, out: str) -> str | None:
    tasks = [r["task"] for r in _records(d)]
    return None if tasks == [TASK] else f"tasks recorded: {tasks!r}"


def summary_escaped(d: Path, out: str) -> str | None:
    text = (d / "run" / "summary.md").read_text() if (d / "run" / "summary.md").exists() else ""
    return "raw HTML in summary.md" if "<img" in text else None


def retryable_record(d: Path, out: str) -> str | None:
    rs = _records(d)
    return None if rs and all(r["retryable"] for r in rs) else "the locked cache was not recorded as retryable"


def no_timeline_mix(d: Path, out: str) -> str | None:
    return None if not (d / "ep" / "timeline.jsonl").exists() else "the second run wrote into the locked folder"


# ---------------------------------------------------------------------------------------------
# Set-ups


def write_record(d: Path, rel: str, **fields: object) -> None:
    """A valid record (of an oracle episode) with ``fields`` changed, at ``d/rel``."""
    base = {"schema_version": 2, "task": TASK, "scene": "tasks_kitchen", "seed": 1, "planner": "oracle",
            "start": "random", "task_progress": 0.5, "actions": [{"step": 0, "name": "done", "ok": True}],
            "high_level_steps": 1}
    (d / rel).parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps({**base, **fields})
    (d / rel).write_text(text + "\n" if rel.endswith(".jsonl") else text)


def run_folder(**fields: object) -> Callable[[Path], None]:
    return lambda d: write_record(d, "run/episodes.jsonl", **fields)


def raw_record(d: Path, text: str) -> None:
    (d / "run").mkdir()
    (d / "run" / "episodes.jsonl").write_text(text)


def torn(name: str) -> Callable[[Path], None]:
    """An episode folder whose ``name`` is cut in the middle of a line."""

    def setup(d: Path) -> None:
        write_record(d, "ep/episode.json")
        (d / "ep" / "timeline.jsonl").write_text('{"step": 0, "frames": 0}\n')
        (d / "ep" / "steps.jsonl").write_text('{"step": 0, "exchanges": []}\n')
        path = d / "ep" / name
        path.write_text(path.read_text()[:17])

    return setup


def symlink(rel: str) -> Callable[[Path], None]:
    def setup(d: Path) -> None:
        (d / "victim.txt").write_text("precious\n")
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).symlink_to(d / "victim.txt")
        if rel.startswith("run/") and rel != "run/.lock":
            write_record(d, "run/episodes.jsonl")

    return setup


def stale_steps(d: Path) -> None:
    (d / "ep").mkdir()
    (d / "ep" / "steps.jsonl").write_text(json.dumps({"step": 0, "exchanges": [
        {"purpose": "plan", "messages": [{"role": "user", "content": "STALE-EXCHANGE"}], "answer": "x",
         "prompt_tokens": 1, "completion_tokens": 1, "latency_s": 0.1}]}) + "\n")


def config(text: str) -> Callable[[Path], None]:
    return lambda d: (d / "llm.toml").write_text(text)


def readonly(rel: str) -> Callable[[Path], None]:
    """A folder even root cannot write (the immutable attribute), holding a run to report on."""

    def setup(d: Path) -> None:
        write_record(d, "run/episodes.jsonl")
        write_record(d, "ep/episode.json")
        (d / "ep" / "timeline.jsonl").write_text("")
        (d / rel).mkdir(parents=True, exist_ok=True)
        subprocess.run(["chattr", "+i", str(d / rel)], check=False)

    return setup


def escaped_scene(d: Path) -> None:
    """The kitchen fixture under a name holding escape sequences."""
    scene = json.loads(KITCHEN.read_text())
    (d / "scene.json").write_text(json.dumps({**scene, "name": f"kitchen_{ESC}"}))


def nested_tasks(d: Path) -> None:
    (d / "tasks.json").write_text("[" * 200_000 + "]" * 200_000)


def bom_tasks(d: Path) -> None:
    (d / "tasks.txt").write_bytes(b"\xef\xbb\xbf" + TASK.encode() + b"\n")


def looping(d: Path) -> None:
    (d / "loop").symlink_to(d / "loop")


def dangling(d: Path) -> None:
    (d / "dangling").symlink_to(d / "nowhere" / "at" / "all")


def run_a(d: Path) -> None:
    """A run of LLM 'openai:a' to resume with another LLM."""
    for seed in (0,):
        write_record(d, "run/episodes.jsonl", llm="openai:a", seed=seed, planner="more")
    (d / "run" / "run.json").write_text(json.dumps({
        "planner": "more", "llm": "openai:a", "tasks": [TASK], "seeds": [0], "episode_fn": FAKE_FN}))


FAKE_FN = "tests.eval.fake_episodes:deterministic_episode"


def eval_fake(fn: str = "deterministic_episode", *, tasks: str = TASK, planner: str = "oracle") -> list[str]:
    """``eval`` of one of the test suite's fake episode functions (no simulation) into {d}/run."""
    return ["eval", "--tasks", tasks, "--planner", planner, "--out", "{d}/run", "--no-progress",
            "--episode-fn", f"tests.eval.fake_episodes:{fn}"]


RUN_LLM = ["run", TASK, "--scene", "{k}", "--planner", "more", "--llm", "openai:fake-model", "--out", "{d}/ep"]
RUN_ORACLE = ["run", TASK, "--scene", "{k}", "--planner", "oracle", "--out", "{d}/ep"]
EVAL_FAKE = eval_fake()
EVAL_LLM = ["eval", "--tasks", TASK, "--scene", "{k}", "--planner", "more", "--llm", "openai:fake-model",
            "--out", "{d}/run", "--no-progress"]
QUICK = "timeout_s = 2.0\nmax_retries = 0\nbackoff_initial_s = 0.01\nbackoff_max_s = 0.02\n"
ESC = "\x1b[31mred\x1b]0;pwned-title\x07\x1b[2J"


CASES: list[Case] = [
    # -- servers ------------------------------------------------------------------------------
    Case("trickling body (1 byte / 0.5 s)", RUN_LLM, 75, [Trickle(Reply("{}" + " " * 400), 0.5)],
         setup=config(QUICK), limit_s=40),
    Case("trickling headers (1 byte / 0.5 s)", RUN_LLM, 75, [Trickle(Reply("{}"), 0.5, headers=True)],
         setup=config(QUICK), limit_s=40),
    Case("200 MB body", RUN_LLM, 1, [Huge(200_000_000)], setup=config(QUICK), limit_s=60),
    Case("200 MB body, no Content-Length", RUN_LLM, 1, [Huge(200_000_000, declare_length=False)],
         setup=config(QUICK), limit_s=60),
    Case("negative usage", RUN_LLM, 0, [Reply(json.dumps({"room": "kitchen"}), prompt_tokens=-300_000_000)] * 3,
         check=record_written_sane),
    Case("1e300 usage", RUN_LLM, 0, [Reply(json.dumps({"room": "kitchen"}), prompt_tokens=1e300)] * 3,
         check=record_written_sane),
    Case("null usage", RUN_LLM, 0, [Reply(json.dumps({"room": "kitchen"}), prompt_tokens=None,
                                          completion_tokens=None)] * 3, check=record_written_sane),
    Case("401 on every request (eval)", EVAL_LLM, 1, [Status(401, "bad key")] * 5),
    Case("ANSI escapes in a server's error", RUN_LLM, 1, [Status(400, f"bad {ESC} request")] * 3),
    Case("locked cache (eval)", EVAL_LLM, 75, [], held_cache=True, check=retryable_record, limit_s=90),
    # -- model strings, URLs, keys, configs -------------------------------------------------------
    Case("key in MORE_AGENT_ROOM_MODEL", RUN_LLM, 2, [], env={"MORE_AGENT_ROOM_MODEL": f"roomy?api_key={KEY}"}),
    Case("base URL 'notaurl'", RUN_LLM, 2, env={"OPENAI_BASE_URL": "notaurl"}),
    Case("base URL 'ftp:'", RUN_LLM, 2, env={"OPENAI_BASE_URL": "ftp://127.0.0.1/v1"}),
    Case("base URL port 99999", RUN_LLM, 2, env={"OPENAI_BASE_URL": "http://127.0.0.1:99999/v1"}),
    Case("key holding CR/LF", RUN_LLM, 2, env={"OPENAI_API_KEY": KEY + "\r\nX-Injected: 1"}),
    Case("timeout_s = inf", RUN_LLM, 2, [], setup=config("timeout_s = inf\n")),
    Case("MORE_AGENT_LLM_CONFIG=/dev/zero", RUN_LLM, 2, [], env={"MORE_AGENT_LLM_CONFIG": "/dev/zero"},
         limits={resource.RLIMIT_AS: 2 << 30}, limit_s=30),
    # -- numbers that cannot be -------------------------------------------------------------------
    Case("eval --seeds 3000000", [*EVAL_FAKE, "--seeds", "3000000"], 2,
         limits={resource.RLIMIT_AS: 2 << 30}, limit_s=30),
    Case("eval --seeds 10^20", [*EVAL_FAKE, "--seeds", str(10**20)], 2, limit_s=30),
    Case("run --seed of 240 digits", [*RUN_ORACLE, "--seed", "7" * 240], 2, limit_s=60),
    Case("record with task_progress 5.0", ["report", "{d}/run"], 2, setup=run_folder(task_progress=5.0)),
    Case("record with NaN", ["report", "{d}/run"], 2,
         setup=lambda d: raw_record(d, '{"task": "t", "scene": "s", "seed": 0, "planner": "oracle", "task_progress": NaN}\n')),
    Case("record with negative cost", ["report", "{d}/run"], 2, setup=run_folder(llm_usage={"cost_usd": -752.52})),
    Case("record of schema 1", ["report", "{d}/run"], 2, setup=run_folder(schema_version=1)),
    Case("record of schema 99", ["report", "{d}/run"], 2, setup=run_folder(schema_version=99)),
    # -- folders that lie ---------------------------------------------------------------------------
    Case("run while another holds the folder", RUN_ORACLE, 2, held_lock="ep/.lock", check=no_timeline_mix),
    Case("run into a folder of another episode", RUN_ORACLE, 2, setup=lambda d: write_record(d, "ep/episode.json"),
         check=earlier_episode_kept),
    Case("run into a folder of an unfinished LLM episode", [*RUN_ORACLE, "--viewer"], 0, setup=stale_steps,
         check=no_stale_exchanges, limit_s=120),
    Case(".lock is a symlink (run)", RUN_ORACLE, 2, setup=symlink("ep/.lock"), check=victim_intact),
    Case(".lock is a symlink (eval)", EVAL_FAKE, 2, setup=symlink("run/.lock"), check=victim_intact),
    Case("episode.json is a symlink (run)", RUN_ORACLE, 0, setup=symlink("ep/episode.json"), check=victim_intact),
    Case("summary.md is a symlink (report --out)", ["report", "{d}/run", "--out", "{d}/run"], 0,
         setup=symlink("run/summary.md"), check=victim_intact),
    Case("eval --resume --allow-mixed with another --llm", [*eval_fake(planner="more"), "--llm", "openai:b", "--resume",
         "--allow-mixed"], 0, setup=run_a, check=mixed_llm_ran),
    Case("eval whose episode function raises", eval_fake("raising_episode", tasks="bad_task"), 1),
    Case("view: torn episode.json", ["view", "{d}/ep"], 2, setup=torn("episode.json")),
    Case("view: torn steps.jsonl", ["view", "{d}/ep"], 2, setup=torn("steps.jsonl")),
    Case("view: torn timeline.jsonl", ["view", "{d}/ep"], 2, setup=torn("timeline.jsonl")),
    Case("path part over 255 characters", [*RUN_ORACLE[:-1], "{d}/" + "x" * 300], 2),
    Case("dangling --out symlink", [*RUN_ORACLE[:-1], "{d}/dangling"], 2, setup=dangling),
    Case("looping --out symlink", [*RUN_ORACLE[:-1], "{d}/loop"], 2, setup=looping),
    Case("read-only report --out", ["report", "{d}/run", "--out", "{d}/ro/sub"], 2, setup=readonly("ro")),
    Case("read-only view --out", ["view", "{d}/ep", "--out", "{d}/ro/sub/v.html"], 2, setup=readonly("ro")),
    Case("disk full during run --viewer", [*RUN_ORACLE, "--viewer"], 75, check=no_empty_record, tmpfs_kb=300,
         limit_s=120),
    Case("--ray-address garbage", [*EVAL_FAKE, "--ray-address", "garbage"], 2, limit_s=60),
    Case("deeply nested task file", eval_fake(tasks="{d}/tasks.json"), 2, setup=nested_tasks),
    Case("task file with a BOM", eval_fake(tasks="{d}/tasks.txt"), 0, setup=bom_tasks, check=task_without_bom),
    Case("ANSI escapes in a scene name", ["run", TASK, "--scene", "{d}/scene.json", "--planner", "oracle", "--out",
         "{d}/ep"], 0, setup=escaped_scene),
    Case("HTML in a model name (summary.md)", [*EVAL_FAKE, "--llm", "openai:<img src=x onerror=alert(1)>"], 0,
         check=summary_escaped),
    # -- signals ------------------------------------------------------------------------------------
    Case("SIGINT during eval (2 workers)", [*eval_fake("slow_episode"), "--seeds", "40", "--workers", "2"], 130,
         env={"FAKE_EPISODE_SECONDS": "0.5"}, signal_after_s=(signal.SIGINT, 8.0)),
    Case("SIGTERM during eval (2 workers)", [*eval_fake("slow_episode"), "--seeds", "40", "--workers", "2"], 143,
         env={"FAKE_EPISODE_SECONDS": "0.5"}, signal_after_s=(signal.SIGTERM, 8.0)),
]


@contextlib.contextmanager
def _held(case: Case, d: Path) -> Iterator[None]:
    """The locks the case holds around its command."""
    with contextlib.ExitStack() as stack:
        if case.held_lock:
            (d / case.held_lock).parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(d / case.held_lock, os.O_RDWR | os.O_CREAT)
            stack.callback(os.close, fd)
            fcntl.flock(fd, fcntl.LOCK_EX)
        if case.held_cache:
            conn = sqlite3.connect(d / "cache.sqlite", isolation_level=None)
            conn.execute("CREATE TABLE IF NOT EXISTS filler (x)")
            conn.execute("BEGIN EXCLUSIVE")
            stack.callback(conn.close)
        yield


def _limits(limits: dict[int, int]) -> Callable[[], None]:
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # over the file-size limit: EFBIG, as a full disk
        for which, value in limits.items():
            resource.setrlimit(which, (value, value))

    return apply


def run_case(case: Case, *, python: str, repo: Path, kitchen: Path) -> dict[str, object]:
    """Run one case; its outcome on every column (True: the case failed on it)."""
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp, FakeOpenAIServer(responder=brain) as server:
        d = Path(tmp)
        server.push(*(case.script or []))
        if case.setup:
            case.setup(d)
        if case.tmpfs_kb:
            (d / "ep").mkdir()
            subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={case.tmpfs_kb}k", "tmpfs", str(d / "ep")], check=True)
        env = {**os.environ, "PYTHONPATH": str(repo), "PYTHONDONTWRITEBYTECODE": "1", "OPENAI_BASE_URL": server.base_url,
               "OPENAI_API_KEY": KEY, "MORE_AGENT_LLM_CACHE": str(d / "cache.sqlite"), "NO_COLOR": "1",
               "MORE_AGENT_LLM_CONFIG": str(d / "llm.toml") if (d / "llm.toml").exists() else ""}
        env.pop("MORE_AGENT_LLM", None)
        env.update({k: v for k, v in case.env.items() if k})
        env = {k: v for k, v in env.items() if v}
        args = [a.replace("{d}", str(d)).replace("{k}", str(kitchen)) for a in case.args]
        cmd = [python, "-c", "from more_agent.cli import app; app(prog_name='more-agent')", *args]
        start = time.perf_counter()
        with _held(case, d):
            proc = subprocess.Popen(cmd, cwd=d, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                    start_new_session=True, preexec_fn=_limits(case.limits) if case.limits else None)
            if case.signal_after_s:
                sig, after = case.signal_after_s
                with contextlib.suppress(subprocess.TimeoutExpired):
                    proc.wait(after)
                with contextlib.suppress(ProcessLookupError):
                    os.kill(proc.pid, sig)
            try:
                out, _ = proc.communicate(timeout=case.limit_s)
                code: int | str = proc.returncode
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                out, _ = proc.communicate()
                code = f"killed after {case.limit_s:g} s"
        text = out.decode("utf-8", "replace")
        problem = case.check(d, text) if case.check else None
        secret = KEY in text or any(KEY.encode() in p.read_bytes() for p in d.rglob("*") if p.is_file() and not p.is_symlink())
        subprocess.run(["chattr", "-R", "-i", str(d)], check=False, capture_output=True)
        if case.tmpfs_kb:
            subprocess.run(["umount", str(d / "ep")], check=True)
        return {
            "case": case.name, "expected": case.expect, "exit": code, "seconds": round(time.perf_counter() - start, 1),
            "traceback": "Traceback" in text or "Exception ignored" in text,
            "wrong exit": code != case.expect,
            "data": problem is not None, "data_problem": problem,
            "secret": secret,
            "terminal": "\x1b" in text,
            "last_line": (text.strip().splitlines() or [""])[-1][:160],
        }


def table(results: list[dict[str, object]]) -> str:
    """The cases x outcome table in Markdown, a totals row last."""
    mark = {True: "FAIL", False: "ok"}
    lines = ["| case | expected | exit | " + " | ".join(COLUMNS) + " |", "|---|---|---|" + "---|" * len(COLUMNS)]
    for r in results:
        lines.append(f"| {r['case']} | {r['expected']} | {r['exit']} | " + " | ".join(mark[bool(r[c])] for c in COLUMNS) + " |")
    totals = " | ".join(str(sum(bool(r[c]) for r in results)) for c in COLUMNS)
    failed = sum(any(r[c] for c in COLUMNS) for r in results)
    lines.append(f"| **{failed} of {len(results)} cases fail** | | | {totals} |")
    return "\n".join(lines)
