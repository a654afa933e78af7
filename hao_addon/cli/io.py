# SPDX-License-Identifier: GPL-3.0-or-later
"""What the command line shows and leaves behind: its own lines only (Blender's and the
importers' output is captured), progress on a terminal, signals as one-line exits, and the
machine-readable ``--json`` report."""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass, field
from typing import Iterator, TextIO

EXIT_INTERRUPTED = {signal.SIGINT: 130, signal.SIGTERM: 143}
REPORT = "the report (--json)"  # its name in collision messages (a report that collides is not written)


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


# Signals received and not yet acted on. Blender prints and swallows an exception raised in
# Python code it calls back (an importer's callback, a property update): a KeyboardInterrupt
# that lands there would be lost, so the signal is also recorded here, and every progress
# step (check_signals) raises it again until the run stops.
_PENDING: list[int] = []
# While positive, a signal is only recorded: raising inside Blender's own initialization
# (``import bpy``, the first GPU context) crashes it (SIGSEGV seen with bpy 5.1).
_DEFER = [0]


def _raise_for(signum: int) -> None:
    if signum == signal.SIGTERM:
        raise Terminated()
    raise KeyboardInterrupt()


def check_signals() -> None:
    """Raise for a signal that arrived and was swallowed on its way (see _PENDING)."""
    if _PENDING:
        _raise_for(_PENDING[0])


def pending_signal() -> int | None:
    """The first signal received in this run, or None: an error raised after one was
    swallowed (an add-on whose registration it interrupted has no operators) is its echo."""
    return _PENDING[0] if _PENDING else None


@contextlib.contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """SIGINT raises KeyboardInterrupt and SIGTERM raises Terminated while inside (the main
    thread only: Python delivers signals there); the previous handlers come back after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_signal(signum, frame):
        _PENDING.append(signum)
        if not _DEFER[0]:
            _raise_for(signum)

    _PENDING.clear()
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        _PENDING.clear()


@contextlib.contextmanager
def deferred_signals() -> Iterator[None]:
    """Run Blender code that must not be interrupted half-way; a signal that arrives meanwhile
    is raised right after it."""
    _DEFER[0] += 1
    try:
        yield
    finally:
        _DEFER[0] -= 1
    if not _DEFER[0]:
        check_signals()


def load_blender(report: "Report"):
    """Import bpy, once a command's arguments and files are checked (a refused run ends in
    a fraction of a second instead of paying Blender's 0.7 s start), and record its version
    in the report. Returns the bpy module."""
    with deferred_signals():
        import bpy
    report.blender = bpy.app.version_string
    return bpy


def exit_process(code: int) -> None:
    """End ``python -m hao_addon`` with exactly this code. bpy's interpreter teardown can
    crash (bpy 4.2 after some registrations, see compat; a signal during a run can leave it
    unsafe), so the process ends at once, after what that teardown would have done for us:
    flushing the streams and removing Blender's session temporary folder."""
    sys.stdout.flush()
    sys.stderr.flush()
    bpy = sys.modules.get("bpy")
    if bpy is not None:
        folder = os.path.normpath(getattr(bpy.app, "tempdir", "") or "")
        if os.path.basename(folder).startswith("blender_") and os.path.isdir(folder):
            shutil.rmtree(folder, ignore_errors=True)
    os._exit(code)


class Progress:
    """Progress on stderr ("hao: baking 'Spot' 45% (2.1 s left)"): on a terminal one
    self-overwriting line, shown once a run has lasted SHOW_AFTER seconds; on a log (stderr not
    a terminal: a farm's or a pipeline's redirect) a whole line every LOG_INTERVAL seconds once
    the run has lasted that long, so a long bake shows it is alive; nothing when disabled."""

    SHOW_AFTER = 1.0
    MIN_INTERVAL = 0.1
    LOG_INTERVAL = 10.0

    def __init__(self, stream: TextIO | None, enabled: bool, terminal: bool = True) -> None:
        self.stream = stream
        self.enabled = enabled and stream is not None
        self.terminal = terminal
        self.start = time.perf_counter()
        self._last = 0.0
        self._shown = False
        self._phase = ""
        self._phase_start = self.start

    def update(self, phase: str, fraction: float | None = None) -> None:
        """phase: what runs now; fraction: of that phase, in [0, 1], or None if unknown.
        Also where a swallowed signal is raised again (check_signals)."""
        check_signals()
        now = time.perf_counter()
        if phase != self._phase:
            self._phase, self._phase_start = phase, now
        if not self.enabled or not self._due(now):
            return
        self._last = now
        text = f"hao: {phase}"
        if fraction is not None and fraction > 0.0:
            left = (now - self._phase_start) * (1.0 - fraction) / fraction
            text += f" {fraction * 100:3.0f}% ({left:.1f} s left)"
        if not self.terminal:
            self.stream.write(text + "\n")
            self.stream.flush()
            return
        self._shown = True  # first: a signal during the write must still get the line cleared
        self.stream.write("\r\033[K" + text)
        self.stream.flush()

    def _due(self, now: float) -> bool:
        if not self.terminal:
            return now - max(self.start, self._last) >= self.LOG_INTERVAL
        return now - self.start >= self.SHOW_AFTER and now - self._last >= self.MIN_INTERVAL

    def share(self, index: int, count: int) -> None:
        """A batch: input index of count starts (the terminal line shows each input's own)."""

    def finish(self) -> None:
        if self._shown:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self._shown = False


class OpenJDProgress:
    """A farm task's progress as Open Job Description reads it from stdout: a line
    'openjd_progress: P' (P in percent of the whole task: a batch's inputs share it) when it
    has grown by a percent or more, and at the end."""

    STEP = 1.0

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self._offset, self._scale = 0.0, 1.0
        self._last = -self.STEP

    def share(self, index: int, count: int) -> None:
        self._offset, self._scale = index / count, 1.0 / count
        self._report(100.0 * self._offset)

    def update(self, phase: str, fraction: float | None = None) -> None:
        check_signals()
        if fraction is not None:
            self._report(100.0 * (self._offset + self._scale * min(max(fraction, 0.0), 1.0)))

    def finish(self) -> None:
        """Nothing to clear (a finished task has said 100 with its last input)."""

    def _report(self, percent: float) -> None:
        if percent - self._last >= self.STEP or (percent >= 100.0 > self._last):
            self._last = percent
            self.stream.write(f"openjd_progress: {percent:.1f}\n")
            self.stream.flush()


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
    # Choices the run made for the user that it says (which of several meshes it baked).
    notes: list = field(default_factory=list)
    # A batch: one report per input (as_dict), and the failed ones' lines.
    inputs: list = field(default_factory=list)
    input_errors: list = field(default_factory=list)
    # Checks of finished bakes that failed (--verify-max-error): the maps are written, the run
    # exits 1 with one line each.
    check_failures: list = field(default_factory=list)
    # A frame sequence: per frame {frame, seconds, reused, outputs} (skipped: true for a frame
    # --skip-existing found current).
    frames: list = field(default_factory=list)
    # --skip-existing: the files found current and kept (listed in outputs too).
    skipped: list = field(default_factory=list)
    # A batch's input: the GPU shader variants it compiled (the first compiles, the rest reuse).
    shaders_compiled: int | None = None
    # A run that failed or was stopped after some of its files were complete (a sequence's
    # finished frames): what is on disk, in words, for the error line; not in the JSON
    # (its outputs list the files).
    kept: str = ""

    @contextlib.contextmanager
    def phase(self, name: str) -> Iterator[None]:
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.timings[name] = round(self.timings.get(name, 0.0) + time.perf_counter() - t0, 4)

    def mark_done(self) -> None:
        """A run that finished: status 'warning' when something in it deserves a look (its
        warnings say what), else 'ok'."""
        self.status = "warning" if self.warnings else "ok"

    def as_dict(self) -> dict:
        out = asdict(self)
        del out["kept"]
        if not self.inputs:  # a single bake's report keeps its shape
            del out["inputs"], out["input_errors"]
        if not self.frames:
            del out["frames"]
        if not self.skipped:
            del out["skipped"]
        if self.shaders_compiled is None:
            del out["shaders_compiled"]
        if not self.notes:
            del out["notes"]
        return out

    def to_json(self) -> str:
        return json.dumps(self.as_dict(), indent=2, default=str) + "\n"
