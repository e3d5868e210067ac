"""Shared CLI plumbing: the exit-status table, clean errors, safe printing of untrusted text, a console.

The exit statuses of every command (the contract of docs/evaluation.md, "Exit status"), decided in
two places only: :func:`episodes_exit_status` for what episodes ended in, :func:`error_exit_status`
for what a command raised.

====  ==========================================================================================
0     every episode ran, whatever it scored
1     a system error in some episode (code raised, the LLM refused the request or the key, a server
      sent a body over the cap), or in the program itself
2     bad input: one line on stderr, before any work where it can be known then; nothing written lost
75    transient (``EX_TEMPFAIL``): episodes hit LLM timeouts, 5xx, a locked cache, a dead worker, or
      the disk filled up; run again (``eval --resume --retry-errors``)
130   interrupted by Ctrl-C (SIGINT); 143 terminated by SIGTERM
====  ==========================================================================================
"""

from __future__ import annotations

import functools
import json
import logging
import os
import sys
import warnings
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, NoReturn, TextIO, TypeVar

import typer
from rich.console import Console
from rich.text import Text

from more_agent.errors import UserError, check_writable_dir
from more_agent.interrupts import interrupted, signal_exit_status, signals_remembered
from more_agent.redaction import for_terminal
from more_agent.safe_files import DISK_FULL_ERRNOS, path_error

if TYPE_CHECKING:  # pydantic's models load only with a command that runs episodes
    from more_agent.records import EpisodeRecord

console = Console()
err_console = Console(stderr=True)

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_RETRYABLE = 75
"""``EX_TEMPFAIL`` of sysexits.h: a temporary failure; running again may succeed."""
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143

MAX_SEED = 2**32 - 1
"""Largest seed (numpy's seeds are 32-bit words; a 240-digit seed would only make a too-long folder name)."""
MAX_SEEDS = 10_000
"""Largest ``eval --seeds`` (10,000 seeds per task is already weeks of episodes)."""
MAX_TRIALS = 100
"""Largest ``eval --trials``."""

F = TypeVar("F", bound=Callable[..., object])

StartOption = Annotated[
    str,
    typer.Option(
        help="Robot start: 'random' (a reachable room, then a pose in it), 'random-area' (uniform over the floor) or 'task-room'."
    ),
]
"""``--start`` of ``run`` and ``eval``."""

DistractorsOption = Annotated[
    bool,
    typer.Option(
        help="Add the scene's own small objects as distractor items (--no-distractors: only the task's objects, as before the harder worlds)."
    ),
]
"""``--distractors/--no-distractors`` of ``run`` and ``eval``."""

DescriptionsOption = Annotated[
    str,
    typer.Option(
        help="Task descriptions: 'named' (the paper's text, naming every goal instance the world makes ambiguous and the "
        "goal conditions it leaves out) or 'paper' (the paper's text verbatim)."
    ),
]
"""``--descriptions`` of ``run`` and ``eval``."""

HistoryOption = Annotated[
    str,
    typer.Option(
        help="Action history of the LLM and VLM planners: 'paper' (the last five actions and every failed one) or "
        "'lasting' (our extension: also every earlier successful grasp, place, open and close)."
    ),
]
"""``--history`` of ``run`` and ``eval``."""

PerceptionOption = Annotated[
    str,
    typer.Option(
        help="Perception: 'gt' (ground truth, the paper's) or 'noisy[:KEY=VALUE,...]' with KEY among confusion, miss, "
        "fragment, merge, depth, drift, room (0 switches one off; 'noisy' alone: every kind at its default rate; "
        "docs/sensors.md#noisy-perception)."
    ),
]
"""``--perception`` of ``run`` and ``eval``."""

SensingOption = Annotated[
    str,
    typer.Option(
        help="Sensing cadence: on the way, the robot's mapper fuses a frame once the base moved DISTANCE or turned "
        "ANGLE since the last one, 'DISTANCEm/ANGLEdeg' (frames where it stops are always fused; 0.5m/30deg: "
        "the cadence before this default; docs/sensors.md#sensing-cadence)."
    ),
]
"""``--sensing`` of ``run`` and ``eval``."""


RoomLLMOption = Annotated[
    str | None,
    typer.Option(
        help="LLM for room classification, e.g. openai:gpt-3.5-turbo as in the paper (default: the planning LLM; "
        "also MORE_AGENT_ROOM_MODEL). Recorded as room_llm in every episode record."
    ),
]
"""``--room-llm`` of ``run`` and ``eval``."""


def use_room_llm(spec: str | None) -> None:
    """Make ``spec`` the room-classification LLM of this process and the workers it starts (through
    ``MORE_AGENT_ROOM_MODEL``, which the planners' LLM config reads); a bad spec fails here."""
    if spec is None:
        return
    from more_agent.llm import parse_llm_spec
    from more_agent.llm.constants import ENV_ROOM_MODEL

    os.environ[ENV_ROOM_MODEL] = str(parse_llm_spec(spec))


BumbleMemoryOption = Annotated[
    Path | None,
    typer.Option(
        help="BUMBLE's long-term memory across runs (its --add_past): a JSON Lines file of failure summaries per "
        "task, read before the episode and appended to after it (eval: --trials N --long-term-memory)."
    ),
]
"""``--bumble-memory`` of ``run``."""


JsonOption = Annotated[
    bool, typer.Option("--json", help="Print JSON (keys documented in docs/cli-json.md) instead of a table.")
]
"""``--json`` of the listing commands and ``report``."""


def print_columns(title: str, header: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
    """A long listing as aligned columns under a bold title and header, the last column left to run on
    (the terminal wraps it). Plain text, never markup. Not a rich Table: it measures, wraps and pads
    each cell, which took 0.5 s of CPU for the 1016 tasks of ``tasks list``."""
    widths = [max([len(h), *(len(row[i]) for row in rows)]) for i, h in enumerate(header[:-1])]

    def line(cells: Sequence[str]) -> str:
        return "  ".join([*(c.ljust(w) for c, w in zip(cells, widths, strict=False)), cells[-1]])

    console.print(title, style="bold", highlight=False, markup=False, soft_wrap=True)
    console.print(line(header), style="bold", highlight=False, markup=False, soft_wrap=True)
    typer.echo("\n".join(for_terminal(line(row)) for row in rows))


def print_json(value: object) -> None:
    """``value`` as indented JSON on stdout (plain text: never read as rich markup)."""
    typer.echo(json.dumps(value, indent=2, ensure_ascii=False))


class _SafeStderrHandler(logging.Handler):
    """Log lines of the package on the current stderr, redacted and clipped (they may quote a server)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            # imported here: the llm package is slow to import, and most commands never log
            from more_agent.llm.limits import MAX_LOG_CHARS, clip

            sys.stderr.write(f"{record.levelname.lower()}: {clip(for_terminal(record.getMessage()), MAX_LOG_CHARS)}\n")
        except Exception:  # noqa: BLE001 - logging must never take the program down
            self.handleError(record)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """Python warnings on stderr without escape sequences (a library warning may quote a scene name)."""
    (file or sys.stderr).write(for_terminal(warnings.formatwarning(message, category, filename, lineno, line)))


def _install_log_handler() -> None:
    """Route the package's log lines through :class:`_SafeStderrHandler` (once per process), and
    print Python warnings as safely."""
    logger = logging.getLogger("more_agent")
    if not any(isinstance(h, _SafeStderrHandler) for h in logger.handlers):
        handler = _SafeStderrHandler(logging.WARNING)
        logger.addHandler(handler)
        logger.propagate = False
    warnings.showwarning = _show_warning


def print_error(message: str) -> None:
    """One red ``error:`` line on stderr; the message is printed as plain text (never as markup),
    redacted, without escape sequences."""
    err_console.print(
        Text.assemble(("error:", "bold red"), " ", for_terminal(message)), highlight=False, soft_wrap=True
    )


def episodes_exit_status(records: Iterable[EpisodeRecord]) -> int:
    """The exit status for what episodes ended in: 1 if one ended in a system error that is not
    transient, else 75 if one ended in a transient one, else 0 (whatever they scored)."""
    from more_agent.eval.episode import ended_abnormally

    abnormal = [r for r in records if ended_abnormally(r)]
    if any(not r.retryable for r in abnormal):
        return EXIT_FAILED
    return EXIT_RETRYABLE if abnormal else EXIT_OK


def error_exit_status(error: UserError | OSError | RecursionError) -> tuple[int, str]:
    """The exit status and the one-line message for what a command raised (any other exception is a
    bug, and keeps its traceback)."""
    if isinstance(error, UserError):
        return EXIT_BAD_INPUT, str(error)
    if isinstance(error, OSError):
        bad_path = path_error(error)
        if bad_path is not None:
            return EXIT_BAD_INPUT, str(bad_path)
        where = f" ({error.filename})" if error.filename else ""
        if error.errno in DISK_FULL_ERRNOS:
            return EXIT_RETRYABLE, f"{error.strerror}{where}: free some space and run it again"
        return EXIT_FAILED, f"{error.strerror or error}{where}"
    return EXIT_BAD_INPUT, "the input is nested too deeply to read"  # a RecursionError


def user_errors_exit_2(fn: F) -> F:
    """Decorate a command: what it raises ends in one line and the status of :func:`error_exit_status`
    (a UserError: 2); Ctrl-C exits 130 and SIGTERM 143, even when native code swallowed the signal."""

    @functools.wraps(fn)
    def wrapper(*args: object, **kwargs: object) -> object:
        _install_log_handler()
        with signals_remembered():
            try:
                result = fn(*args, **kwargs)
            except KeyboardInterrupt:
                _interrupted()
            except (UserError, OSError, RecursionError) as e:
                if interrupted():
                    _interrupted()
                code, message = error_exit_status(e)
                print_error(message)
                raise typer.Exit(code=code) from None
            if interrupted():
                _interrupted()
        return result

    return wrapper  # type: ignore[return-value]


def _interrupted() -> NoReturn:
    err_console.print("interrupted", style="yellow", highlight=False)
    raise typer.Exit(code=signal_exit_status())


def check_output_file(path: Path) -> None:
    """Raise a UserError unless ``path`` can be written as a file (checked before any work starts)."""
    if path.is_dir():
        raise UserError(f"--out {path} is a directory; give a file name")
    check_writable_dir(path.parent)
