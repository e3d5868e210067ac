"""The evaluation harness: task-set expansion, episode execution in processes or on Ray, resumable runs.

The harness knows only an *episode function* ``fn(spec: EpisodeSpec, *, out_dir: Path) ->
EpisodeRecord``, named by a dotted path (``"package.module:function"``) so that any worker process
or Ray node can import it; the default is ``more_agent.eval.episode:run_episode``, resolved lazily.
Records are appended to ``DIR/episodes.jsonl`` by this (parent) process only, as they finish.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

from more_agent.errors import UserError, unknown_name_error
from more_agent.eval.runlock import locked_run_dir
from more_agent.eval.store import (
    EPISODES_FILE,
    EpisodeWriter,
    RunConfig,
    check_run_dir,
    episode_dir,
    index_records,
    pending,
    prepare_run_dir,
    recorded,
    retire_retryable,
    with_past_failures,
)
from more_agent.eval.worker import error_record, execute_episode, resolve_episode_fn
from more_agent.interrupts import ignore_interrupts, interrupted
from more_agent.llm.concurrency import LLMConcurrencyLimiter, ProcessLimiter, set_llm_limiter
from more_agent.records import EpisodeRecord, EpisodeSpec, episode_settings
from more_agent.safe_files import read_bounded

DEFAULT_EPISODE_FN = "more_agent.eval.episode:run_episode"
"""Dotted path of the real episode function."""
VIEWER_EPISODE_FN = "more_agent.eval.viewer:run_episode_with_viewer"
"""The real episode function that also writes each episode's viewer (``more-agent eval --viewer``)."""

DEFAULT_MAX_RETRIES = 2
"""Re-runs of an episode whose worker process died before it is recorded as an error."""

MAX_TASK_FILE_BYTES = 1024 * 1024
"""Largest ``--tasks`` file read (about 30,000 task names)."""


# ---------------------------------------------------------------------------------------------
# What to run


def check_task_names(names: Iterable[str]) -> None:
    """Raise a UserError naming the closest activities for the first unknown task name."""
    from more_agent.sim.tasks import task_names

    known = set(task_names())
    for name in names:
        if name not in known:
            raise unknown_name_error("task", name, sorted(known))


def resolve_tasks(arg: str, *, task_set: Callable[[str], list[str]] | None = None) -> list[str]:
    """Task names from ``--tasks``: a set name, a file (one name per line or a JSON list), or 'a,b,c'.

    Duplicates are dropped, order kept. Lines starting with '#' in a file are comments.
    """
    from more_agent.sim import tasks  # lazy: workers need no task catalogue

    arg = arg.strip()
    path = Path(arg)
    if arg in tasks.TASK_SETS:
        names = (task_set or tasks.task_set)(arg)
    elif _is_file(path):
        text = read_bounded(path, what="task file", max_bytes=MAX_TASK_FILE_BYTES)  # a byte-order mark dropped
        if text.lstrip().startswith("["):
            try:
                names = json.loads(text)
            except (json.JSONDecodeError, RecursionError) as e:
                raise UserError(
                    f"{path}: not a JSON list of task names: {str(e)[:200] or 'nested too deeply'}"
                ) from None
            if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
                raise UserError(f"{path}: expected a JSON list of task names (strings)")
        else:
            names = [ln.strip() for ln in text.splitlines() if ln.strip() and not ln.strip().startswith("#")]
    elif "/" in arg or arg.endswith((".txt", ".json")):
        raise UserError(f"task file {arg} does not exist")
    else:
        names = [n.strip() for n in arg.split(",") if n.strip()]
    names = list(dict.fromkeys(n.strip() for n in names))
    if not names:
        raise UserError(f"--tasks {arg!r} names no task; use a set ({', '.join(tasks.TASK_SETS)}), a file or 'a,b,c'")
    return names


def _is_file(path: Path) -> bool:
    """``path.is_file()``, False for strings no file can be named (too long, NUL bytes)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def config_specs(config: RunConfig) -> list[EpisodeSpec]:
    """Every episode of a run: trials x tasks x seeds, trial-major (the trials of a world run in sequence)."""
    return [
        EpisodeSpec(
            task=t,
            scene=config.scene,
            seed=s,
            trial=k,
            planner=config.planner,
            **episode_settings(config),
        )
        for k in range(config.trials)
        for t in config.tasks
        for s in config.seeds
    ]


def _exit_when_orphaned(parent_pid: int) -> None:
    while os.getppid() == parent_pid:
        time.sleep(0.5)
    os._exit(1)


def _init_worker(limiter: LLMConcurrencyLimiter | None, parent_pid: int) -> None:
    """Pool worker start-up: leave Ctrl-C to the parent, install the shared LLM limiter, exit if the parent dies."""
    ignore_interrupts()
    set_llm_limiter(limiter)
    threading.Thread(target=_exit_when_orphaned, args=(parent_pid,), daemon=True).start()


def iter_inline(specs: Sequence[EpisodeSpec], *, fn_path: str, run_dir: Path) -> Iterator[EpisodeRecord]:
    """Run episodes one after another in this process."""
    for spec in specs:
        yield execute_episode(fn_path, spec, str(run_dir))


def iter_processes(
    specs: Sequence[EpisodeSpec],
    *,
    fn_path: str,
    run_dir: Path,
    workers: int,
    start_method: str = "spawn",
    max_concurrent_llm: int | None = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
) -> Iterator[EpisodeRecord]:
    """Run episodes in a process pool, yielding records as they finish.

    When a worker dies the pool breaks and every episode then in flight fails with it; only the
    one that died is to blame, but the pool does not say which. So the episodes in flight become
    *suspects* and are re-run one at a time in a fresh pool: a death is charged to an episode only
    when it was the only one that failed with its pool. An episode charged more than
    ``max_retries`` deaths is recorded as a retryable ``WorkerDied`` error.
    """
    ctx = multiprocessing.get_context(start_method)
    limiter = ProcessLimiter.create(ctx, max_concurrent_llm) if max_concurrent_llm else None
    queue = deque(range(len(specs)))
    deaths = [0] * len(specs)
    suspects: set[int] = set()
    while queue:
        pool = ProcessPoolExecutor(
            max_workers=min(workers, len(queue)),
            mp_context=ctx,
            initializer=_init_worker,
            initargs=(limiter, os.getpid()),
        )
        inflight: dict[Future[EpisodeRecord], int] = {}
        failed: list[int] = []
        try:
            while inflight or (queue and not failed):
                while queue and not failed and len(inflight) < workers and _may_start(queue[0], inflight, suspects):
                    i = queue.popleft()
                    try:
                        inflight[pool.submit(execute_episode, fn_path, specs[i], str(run_dir))] = i
                    except BrokenProcessPool:
                        queue.appendleft(i)
                        failed.append(-1)  # the pool broke between two submissions: no episode to blame
                        break
                done, _ = wait(inflight, return_when=FIRST_COMPLETED)
                for fut in done:
                    i = inflight.pop(fut)
                    try:
                        record = fut.result()
                    except BrokenProcessPool:
                        failed.append(i)
                        continue
                    suspects.discard(i)
                    yield record
        except BaseException:  # Ctrl-C, SIGTERM, a closed generator: stop the episodes in flight now
            _stop_workers()
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        victims = [i for i in failed if i >= 0]
        if len(victims) == 1:
            deaths[victims[0]] += 1
        else:
            suspects.update(victims)
        for i in victims:
            if deaths[i] > max_retries:
                yield error_record(specs[i], f"WorkerDied: worker process died {deaths[i]} times", retryable=True)
        queue.extendleft(reversed([i for i in victims if deaths[i] <= max_retries]))


def _stop_workers() -> None:
    """Terminate this process's worker processes (they ignore Ctrl-C; the parent decides when they stop)."""
    for child in multiprocessing.active_children():
        child.terminate()
    for child in multiprocessing.active_children():
        child.join(timeout=5)


def _may_start(i: int, inflight: dict[Future[EpisodeRecord], int], suspects: set[int]) -> bool:
    """Whether episode ``i`` may join the episodes in flight: a suspect runs alone."""
    return not inflight or (i not in suspects and not suspects.intersection(inflight.values()))


# ---------------------------------------------------------------------------------------------
# A whole run


def _progress(console: Console, *, show: bool) -> Progress:
    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("SR {task.fields[sr]}"),
        TextColumn("errors {task.fields[errors]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=console,
        disable=not show,
    )


def evaluate(
    config: RunConfig,
    run_dir: Path,
    *,
    resume: bool = False,
    retry_errors: bool = False,
    allow_mixed: bool = False,
    max_concurrent_llm: int | None = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
    start_method: str = "spawn",
    show_progress: bool = True,
    console: Console | None = None,
) -> list[EpisodeRecord]:
    """Run every missing episode of ``config`` into ``run_dir`` and return all of the run's records.

    Workers: ``config.ray_address`` set -> Ray (``'local'`` starts a local Ray); else
    ``config.workers`` > 1 -> a process pool; else this process. The run folder is locked for the
    whole run (a second writer gets a UserError naming the holder). With ``retry_errors`` (and
    ``resume``) the episodes recorded with a retryable error are run again.
    """
    run_dir = Path(run_dir)
    resolve_episode_fn(config.episode_fn)  # fail early, in the parent, on a bad path
    if retry_errors and not resume:
        raise UserError("--retry-errors re-runs the retryable errors of an existing run: pass --resume too")
    check_run_dir(run_dir)
    with locked_run_dir(run_dir):
        records = prepare_run_dir(run_dir, config, resume=resume, allow_mixed=allow_mixed)
        if retry_errors:
            records = retire_retryable(run_dir, records)
        if resume and config.episode_fn == DEFAULT_EPISODE_FN:
            redraw_missing_maps(config, run_dir, records)
        return _run_pending(
            config,
            run_dir,
            records,
            max_concurrent_llm=max_concurrent_llm,
            max_retries=max_retries,
            start_method=start_method,
            show_progress=show_progress,
            console=console,
        )


def redraw_missing_maps(config: RunConfig, run_dir: Path, records: list[EpisodeRecord]) -> int:
    """Redraw the ``map.png`` of recorded episodes whose picture is missing or torn (none while pictures are
    off, ``eval.pictures``); return how many."""
    from more_agent.eval.episode import redraw_map
    from more_agent.eval.episode_folder import MAP_FILE, map_is_complete
    from more_agent.eval.pictures import pictures_enabled

    if not pictures_enabled():
        return 0
    index = index_records(records)
    redrawn = 0
    for spec in config_specs(config):
        record = recorded(spec, index)
        out_dir = episode_dir(run_dir, spec)
        if record is None or not record.trajectory or not out_dir.is_dir() or map_is_complete(out_dir / MAP_FILE):
            continue
        try:
            redraw_map(spec, record, out_dir)
        except Exception as e:  # noqa: BLE001 - a picture that cannot be redrawn must not stop the run
            Console(stderr=True).print(
                f"cannot redraw {out_dir / MAP_FILE}: {type(e).__name__}: {e}", markup=False, highlight=False
            )
            continue
        redrawn += 1
    return redrawn


def _run_pending(
    config: RunConfig,
    run_dir: Path,
    records: list[EpisodeRecord],
    *,
    max_concurrent_llm: int | None,
    max_retries: int,
    start_method: str,
    show_progress: bool,
    console: Console | None,
) -> list[EpisodeRecord]:
    """Run the episodes of ``config`` that have no record in ``records``, appending to the locked run folder.

    Trials run in rounds: trial k of every world, then trial k + 1, each given (with ``long_term_memory``)
    the failure summaries the records of its world's earlier trials hold (:func:`with_past_failures`).
    A trial whose earlier trials have no result yet is held back and said so.
    """
    todo = pending(config_specs(config), records)
    console = console or Console(stderr=True)
    held = 0
    with EpisodeWriter(run_dir / EPISODES_FILE) as writer, _progress(console, show=show_progress) as bar:
        successes, errors = sum(r.success for r in records), sum(r.error is not None for r in records)
        done = len(records)

        def fields() -> dict[str, Any]:
            return {"sr": f"{successes / done:.1%}" if done else "-", "errors": str(errors)}

        bar_id = bar.add_task(config.planner, total=len(todo), **fields())
        for trial in range(config.trials):
            ready = [with_past_failures(s, records) for s in todo if s.trial == trial]
            held += sum(s is None for s in ready)
            runnable = [s for s in ready if s is not None]
            for record in _stream(config, runnable, run_dir, max_concurrent_llm, max_retries, start_method):
                if interrupted():  # Ctrl-C that native code turned into an ordinary error: not a result
                    raise KeyboardInterrupt
                writer.append(record)
                records.append(record)
                done, successes, errors = done + 1, successes + record.success, errors + (record.error is not None)
                bar.update(bar_id, advance=1, **fields())
    if held:
        console.print(
            f"{held} trial(s) wait for an earlier trial of their world that has no result yet (a retryable error): "
            "run them with --resume --retry-errors",
            style="yellow",
            markup=False,
            highlight=False,
        )
    return records


def _stream(
    config: RunConfig,
    todo: Sequence[EpisodeSpec],
    run_dir: Path,
    max_concurrent_llm: int | None,
    max_retries: int,
    start_method: str,
) -> Iterable[EpisodeRecord]:
    """The records of ``todo`` as they finish: on Ray, in a process pool, or in this process (``config``)."""
    if not todo:
        return []
    if config.ray_address:
        from more_agent.eval.ray_backend import iter_ray

        return iter_ray(
            todo,
            fn_path=config.episode_fn,
            run_dir=run_dir,
            address=config.ray_address,
            max_concurrent_llm=max_concurrent_llm,
            max_retries=max_retries,
        )
    if config.workers > 1 and len(todo) > 1:
        return iter_processes(
            todo,
            fn_path=config.episode_fn,
            run_dir=run_dir,
            workers=config.workers,
            start_method=start_method,
            max_concurrent_llm=max_concurrent_llm,
            max_retries=max_retries,
        )
    return iter_inline(todo, fn_path=config.episode_fn, run_dir=run_dir)
