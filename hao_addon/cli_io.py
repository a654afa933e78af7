# SPDX-License-Identifier: GPL-3.0-or-later
"""What the command line shows and leaves behind: its own lines only (Blender's and the
importers' output is captured), progress on a terminal, signals as one-line exits, and the
machine-readable ``--json`` report."""
from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass, field
from typing import Iterator, TextIO

EXIT_INTERRUPTED = {signal.SIGINT: 130, signal.SIGTERM: 143}


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so every ``finally`` runs (temporary files,
    the unwrap child, GPU passes) and the process exits 143."""


class ProcessOutput:
    """While entered, file descriptors 1 and 2 lead to a temporary file, so whatever Blender,
    its importers, Mesa or a C library print is kept out of the user's streams; ``out`` and
    ``err`` write to the original ones. ``log()`` returns what was captured."""

    def __enter__(self) -> "ProcessOutput":
        sys.stdout.flush()
        sys.stderr.flush()
        self._saved = (os.dup(1), os.dup(2))
        self._log = tempfile.TemporaryFile()
        os.dup2(self._log.fileno(), 1)
        os.dup2(self._log.fileno(), 2)
        self.out: TextIO = os.fdopen(os.dup(self._saved[0]), "w", buffering=1, encoding="utf-8", errors="replace")
        self.err: TextIO = os.fdopen(os.dup(self._saved[1]), "w", buffering=1, encoding="utf-8", errors="replace")
        self.err_is_terminal = os.isatty(self._saved[1])
        return self

    def log(self) -> str:
        sys.stdout.flush()
        sys.stderr.flush()
        self._log.seek(0)
        return self._log.read().decode(errors="replace")

    def __exit__(self, *exc) -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        self.out.close()
        self.err.close()
        for fd, saved in zip((1, 2), self._saved):
            os.dup2(saved, fd)
            os.close(saved)
        self._log.close()


@contextlib.contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """SIGINT raises KeyboardInterrupt and SIGTERM raises Terminated while inside (the main
    thread only: Python delivers signals there); the previous handlers come back after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_term(signum, frame):
        raise Terminated()

    previous = {signal.SIGINT: signal.signal(signal.SIGINT, signal.default_int_handler),
                signal.SIGTERM: signal.signal(signal.SIGTERM, on_term)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


class Progress:
    """One self-overwriting line on a terminal's stderr ("hao: baking 'Spot' 45% (2.1 s left)"),
    shown once a run has lasted SHOW_AFTER seconds; nothing when disabled."""

    SHOW_AFTER = 1.0
    MIN_INTERVAL = 0.1

    def __init__(self, stream: TextIO | None, enabled: bool) -> None:
        self.stream = stream
        self.enabled = enabled and stream is not None
        self.start = time.perf_counter()
        self._last = 0.0
        self._shown = False
        self._phase = ""
        self._phase_start = self.start

    def update(self, phase: str, fraction: float | None = None) -> None:
        """phase: what runs now; fraction: of that phase, in [0, 1], or None if unknown."""
        now = time.perf_counter()
        if phase != self._phase:
            self._phase, self._phase_start = phase, now
        if not self.enabled or now - self.start < self.SHOW_AFTER or now - self._last < self.MIN_INTERVAL:
            return
        self._last = now
        text = f"hao: {phase}"
        if fraction is not None and fraction > 0.0:
            left = (now - self._phase_start) * (1.0 - fraction) / fraction
            text += f" {fraction * 100:3.0f}% ({left:.1f} s left)"
        self.stream.write("\r\033[K" + text)
        self.stream.flush()
        self._shown = True

    def finish(self) -> None:
        if self._shown:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self._shown = False


@dataclass
class Report:
    """The ``--json`` report: what ran, on what, with which settings, how long each phase
    took, what was written, the warnings, and the error if any."""

    command: str
    input: str = ""
    status: str = "ok"
    exit_code: int = 0
    error: str | None = None
    blender: str = ""
    hao: str = ""
    objects: list = field(default_factory=list)
    settings: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    outputs: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    @contextlib.contextmanager
    def phase(self, name: str) -> Iterator[None]:
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.timings[name] = round(self.timings.get(name, 0.0) + time.perf_counter() - t0, 4)

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2, default=str) + "\n"
