# SPDX-License-Identifier: GPL-3.0-or-later
"""Stepped work: the long jobs (unwrap, projection, bake rounds, the Blender job) are
generators that yield progress and return their result, so a caller can report progress,
stay responsive and stop them between steps. These two helpers are the only loops that
drive one; both close it however they end (a cancel frees its GPU pass or child process
at once, not at garbage collection)."""
from __future__ import annotations

from typing import Any, Callable, Generator


def relay(steps: Generator, each: Callable[[Any], Any] = lambda step: step) -> Generator[Any, None, Any]:
    """Yield each(step) for every step of `steps` (``result = yield from relay(...)``);
    returns its value."""
    try:
        while True:
            try:
                step = next(steps)
            except StopIteration as stop:
                return stop.value
            yield each(step)
    finally:
        steps.close()


def drain(steps: Generator, progress: Callable[[Any], None] | None = None) -> Any:
    """Run `steps` to its end, calling progress(step) for each step; returns its value."""
    relayed = relay(steps, progress or (lambda step: None))
    try:
        while True:
            next(relayed)
    except StopIteration as stop:
        return stop.value
    finally:
        relayed.close()  # closes steps too
