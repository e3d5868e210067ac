"""Shared CLI plumbing: exit statuses, clean errors, safe printing of untrusted text, a rich console.

Exit statuses of every command: 0 done; 1 an episode or the program itself failed (a bug, an LLM
that refused the request); 2 bad input (one line on stderr, nothing written lost); 75 the run ended
but some episodes hit transient errors (LLM transport, worker deaths): re-run them with
``--resume --retry-errors``; 130 interrupted by Ctrl-C.
"""

from __future__ import annotations

import functools
import json
import logging
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, TypeVar

import typer
from rich.console import Console
from rich.text import Text

from more_agent.errors import UserError, check_writable_dir
from more_agent.interrupts import interrupted, sigint_remembered
from more_agent.redaction import redact

console = Console()
err_console = Console(stderr=True)

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_RETRYABLE = 75
"""``EX_TEMPFAIL`` of sysexits.h: a temporary failure; running again may succeed."""
EXIT_INTERRUPTED = 130

F = TypeVar("F", bound=Callable[..., object])

StartOption = Annotated[str, typer.Option(
    help="Robot start: 'random' (a reachable room, then a pose in it), 'random-area' (uniform over the floor) or 'task-room'."
)]
"""``--start`` of ``run`` and ``eval``."""

DistractorsOption = Annotated[bool, typer.Option(
    help="Add the scene's own small objects as distractor items (--no-distractors: only the task's objects, as before the harder worlds)."
)]
"""``--distractors/--no-distractors`` of ``run`` and ``eval``."""

JsonOption = Annotated[bool, typer.Option("--json", help="Print JSON (keys documented in docs/cli-json.md) instead of a table.")]
"""``--json`` of the listing commands and ``report``."""


def print_json(value: object) -> None:
    """``value`` as indented JSON on stdout (plain text: never read as rich markup)."""
    typer.echo(json.dumps(value, indent=2, ensure_ascii=False))


class _SafeStderrHandler(logging.Handler):
    """Log lines of the package on the current stderr, redacted and clipped (they may quote a server)."""

    def emit(self, record: logging.LogRecord) -> None:
        # imported here: the llm package is slow to import, and most commands never log
        from more_agent.llm.limits import MAX_LOG_CHARS, clip

        try:
            sys.stderr.write(f"{record.levelname.lower()}: {clip(redact(record.getMessage()), MAX_LOG_CHARS)}\n")
        except Exception:  # noqa: BLE001 - logging must never take the program down
            self.handleError(record)


def _install_log_handler() -> None:
    """Route the package's warnings through :class:`_SafeStderrHandler` (once per process)."""
    logger = logging.getLogger("more_agent")
    if not any(isinstance(h, _SafeStderrHandler) for h in logger.handlers):
        handler = _SafeStderrHandler(logging.WARNING)
        logger.addHandler(handler)
        logger.propagate = False


def print_error(message: str) -> None:
    """One red ``error:`` line on stderr; the message is printed as plain text (never as markup), redacted."""
    err_console.print(Text.assemble(("error:", "bold red"), " ", redact(message)), highlight=False, soft_wrap=True)


def user_errors_exit_2(fn: F) -> F:
    """Decorate a command: a UserError prints one red line and exits 2; Ctrl-C, even a swallowed one, exits 130."""

    @functools.wraps(fn)
    def wrapper(*args: object, **kwargs: object) -> object:
        _install_log_handler()
        with sigint_remembered():
            try:
                result = fn(*args, **kwargs)
            except UserError as e:
                print_error(str(e))
                raise typer.Exit(code=EXIT_BAD_INPUT) from None
            except KeyboardInterrupt:
                err_console.print("interrupted", style="yellow", highlight=False)
                raise typer.Exit(code=EXIT_INTERRUPTED) from None
            if interrupted():
                err_console.print("interrupted", style="yellow", highlight=False)
                raise typer.Exit(code=EXIT_INTERRUPTED)
        return result

    return wrapper  # type: ignore[return-value]


def check_output_file(path: Path) -> None:
    """Raise a UserError unless ``path`` can be written as a file (checked before any work starts)."""
    if path.is_dir():
        raise UserError(f"--out {path} is a directory; give a file name")
    check_writable_dir(path.parent)
