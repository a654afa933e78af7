# SPDX-License-Identifier: GPL-3.0-or-later
"""The command line's exit codes and its one-line failure messages."""
from __future__ import annotations

import os
import traceback

from .io import EXIT_INTERRUPTED, pending_signal, ProcessOutput, Terminated
from ..core.errors import GPUUnavailableError, UserInputError


EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT, EXIT_NO_GPU = 0, 1, 2, 3


DEBUG_ENV = "HAO_DEBUG"  # set to 1: an internal error also prints its traceback and Blender's log


class CLIError(Exception):
    def __init__(self, message: str, code: int = EXIT_BAD_INPUT) -> None:
        super().__init__(message)
        self.code = code


def last_line(exc: BaseException) -> str:
    lines = [l.strip() for l in str(exc).strip().splitlines() if l.strip()]
    text = lines[-1] if lines else type(exc).__name__
    return text.removeprefix("Error: ")


def failure(exc: BaseException, io: ProcessOutput | None) -> tuple[int, str]:
    """(exit code, one-line message) for any exception (io: where HAO_DEBUG writes the
    traceback; None for a batch input's failure, which carries on)."""
    import signal

    if pending_signal() is not None and not isinstance(exc, (KeyboardInterrupt, Terminated)):
        exc = Terminated() if pending_signal() == signal.SIGTERM else KeyboardInterrupt()
    if isinstance(exc, KeyboardInterrupt):
        return EXIT_INTERRUPTED[signal.SIGINT], "interrupted (SIGINT): nothing was written"
    if isinstance(exc, Terminated):
        return EXIT_INTERRUPTED[signal.SIGTERM], "terminated (SIGTERM): nothing was written"
    if isinstance(exc, CLIError):
        return exc.code, str(exc)
    if isinstance(exc, GPUUnavailableError):
        return EXIT_NO_GPU, last_line(exc)
    if isinstance(exc, (UserInputError, OSError)):  # bake and view input, UnwrapError, SettingError
        return EXIT_BAD_INPUT, last_line(exc)
    if os.environ.get(DEBUG_ENV) and io is not None:
        io.err.write(io.log() + "".join(traceback.format_exception(exc)))
    return EXIT_FAILURE, (f"internal error ({type(exc).__name__}: {last_line(exc)}); "
                          f"run with {DEBUG_ENV}=1 for details")
