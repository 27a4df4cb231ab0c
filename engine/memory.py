"""Python's cycle collector: paused while a large structure is built, and spared the walks a
command's start and exit would make over objects that live as long as the process.

Building a large structure allocates objects faster than they die, so the collector runs again
and again over everything built so far, and its cost grows with the square of the size. The
structures built under the pause (a batch of planned programs, an ezdxf document) are
freed by reference counting or collected once, after the pause."""
from __future__ import annotations

import atexit
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


# Python's default starts a young collection every 700 objects allocated and not yet freed; the
# start of a command allocates some 60,000 that live until it ends (modules, classes, functions,
# tables), so the collector ran about 90 times over them and found nothing (8 ms of the 0.2 s of
# `engine instantiate --gear 42`, issue 28). Every 100,000 it still runs during long work, each
# collection over as many objects, so the total stays the same; young garbage waits for at most
# that many allocations, and what outlived a young collection for an older one, ten young ones
# later as before.
COMMAND_YOUNG_COLLECTION = 100_000
_exit_without_collection = False


@contextlib.contextmanager
def command_collection():
    """The cycle collector as a command run from the shell wants it, while the command runs:
    young collections every COMMAND_YOUNG_COLLECTION objects (none during its start), and none
    at the exit. At its exit Python collects once more over everything still alive (every module,
    class and function: about 20 ms of a short command) before the process ends and the system
    takes its memory back whole; gc.freeze, registered as an exit handler, leaves it to the
    system. Buffered files are flushed by Python's exit all the same, the database connections
    are closed by their `with` blocks, and no __del__ of what is alive at exit is promised
    (the Python reference, object.__del__)."""
    global _exit_without_collection
    thresholds = gc.get_threshold()
    gc.set_threshold(max(COMMAND_YOUNG_COLLECTION, thresholds[0]), *thresholds[1:])
    if not _exit_without_collection:
        atexit.register(gc.freeze)
        _exit_without_collection = True
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)
