"""Episodes as Ray tasks (optional extra: ``pip install 'more-agent[ray]'``).

One idempotent task per episode (it writes only its own ``DIR/episodes/<key>/``; the driver appends
the returned record), retried up to ``max_retries`` times when its worker dies, and one
``RayLimiter`` actor that bounds concurrent LLM calls across every worker of the cluster. On a
multi-node cluster the per-episode files stay on the node that ran the episode unless ``DIR`` is a
shared filesystem; ``episodes.jsonl`` is always written by the driver.
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

from more_agent.errors import UserError
from more_agent.eval.worker import error_record, execute_episode
from more_agent.llm.concurrency import SlotContext, set_llm_limiter
from more_agent.records import EpisodeRecord, EpisodeSpec


def import_ray() -> ModuleType:
    """The ``ray`` module, or a UserError naming the extra to install."""
    try:
        import ray
    except ImportError:
        raise UserError("Ray is not installed; install the extra: pip install 'more-agent[ray]'") from None
    return ray


class _Semaphore:
    """Ray actor body: an asyncio semaphore whose acquire waits without blocking the actor."""

    def __init__(self, max_concurrent: int) -> None:
        self._sem = asyncio.Semaphore(max_concurrent)

    async def acquire(self) -> None:
        await self._sem.acquire()

    async def release(self) -> None:
        self._sem.release()


class RayLimiter(SlotContext):
    """An ``LLMConcurrencyLimiter`` backed by a Ray actor, shared by every task that holds it.

    A slot held by a worker that dies is not given back; size the limit with that in mind.
    """

    def __init__(self, actor: Any) -> None:
        self._actor = actor

    @classmethod
    def create(cls, max_concurrent: int) -> RayLimiter:
        """Start the semaphore actor (Ray must be initialised)."""
        if max_concurrent < 1:
            raise ValueError(f"max_concurrent must be >= 1, got {max_concurrent}")
        ray = import_ray()
        return cls(ray.remote(num_cpus=0)(_Semaphore).remote(max_concurrent))

    def acquire(self) -> None:
        """Block until the actor grants a slot."""
        import_ray().get(self._actor.acquire.remote())

    def release(self) -> None:
        """Give the slot back."""
        import_ray().get(self._actor.release.remote())


def _ray_episode(fn_path: str, spec: EpisodeSpec, run_dir: str, limiter: RayLimiter | None) -> EpisodeRecord:
    """Body of the Ray task: install the shared limiter, run the episode."""
    set_llm_limiter(limiter)
    return execute_episode(fn_path, spec, run_dir)


def iter_ray(
    specs: Sequence[EpisodeSpec],
    *,
    fn_path: str,
    run_dir: Path,
    address: str = "local",
    max_concurrent_llm: int | None = None,
    max_retries: int = 2,
    num_cpus: int | None = None,
) -> Iterator[EpisodeRecord]:
    """Run episodes as Ray tasks, yielding records as they finish.

    ``address``: a cluster address (``'auto'``, ``'ray://host:10001'``) or ``'local'`` to start a
    local Ray with ``num_cpus`` CPUs (shut down again at the end). An already initialised Ray is
    used as it is.
    """
    ray = import_ray()
    started = False
    if not ray.is_initialized():
        try:
            if address == "local":
                ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
            else:
                ray.init(address=address, log_to_driver=False)
        except (ConnectionError, ValueError, RuntimeError) as e:
            raise UserError(f"cannot start or reach Ray at {address!r}: {str(e).splitlines()[0][:200]}") from None
        started = True
    try:
        limiter = RayLimiter.create(max_concurrent_llm) if max_concurrent_llm else None
        task = ray.remote(max_retries=max_retries, retry_exceptions=False)(_ray_episode)
        refs = {task.remote(fn_path, spec, str(run_dir), limiter): spec for spec in specs}
        while refs:
            done, _ = ray.wait(list(refs), num_returns=1)
            for ref in done:
                spec = refs.pop(ref)
                try:
                    record = ray.get(ref)
                except ray.exceptions.RayError as e:
                    record = error_record(
                        spec, f"WorkerDied: {type(e).__name__} after {max_retries} retries: {e}", retryable=True
                    )
                yield record
    finally:
        if started:
            ray.shutdown()
