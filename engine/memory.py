"""Pausing Python's cycle collector while a large structure is built.

Building one allocates objects faster than they die, so the collector runs again and again
over everything built so far, and its cost grows with the square of the size. The
structures built under the pause (a batch of planned programs, an ezdxf document) are
freed by reference counting or collected once, after the pause."""
from __future__ import annotations

import contextlib
import gc


@contextlib.contextmanager
def no_cycle_collection():
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
