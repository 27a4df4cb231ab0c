"""Planning a batch across cores: `engine instantiate --gears A-B --workers N`.

The Planner is made ready in this process (machine, hob library, case base, and the model and
compiled template of every class in the batch), then N worker processes are forked from it and
plan slices of the gears; they read nothing from the database (the connection they inherit is
never touched). Their jobs come back here in gear order and are stored in one transaction by
the caller, so a batch is still all or none. A bad gear does not stop the workers: it comes back
as its reason (engine.programs.batches.Bad), so the batch names every bad gear in one run.

Ctrl-C reaches every process of the terminal's process group, the workers too. A worker ignores
it (issue 31: each printed `Process ForkPoolWorker-N:` and a traceback): the parent alone stops,
its transaction rolled back, and ends the workers as it leaves the pool (terminate).
"""
from __future__ import annotations

import contextlib
import gc
import multiprocessing
import signal

from ..errors import EngineError
from ..templates.decision_table import compiled_template
from .options import PLANNING, RunMode

SLICES_PER_WORKER = 8   # small enough to balance the workers, large enough to amortise sending jobs

_BATCH: list = []   # (planner, gears, plan function) of the batch being planned, inherited by the forked workers


def plan_in_workers(planner, gears: list, plan_one, mode: RunMode, each_slice=None) -> list:
    """`plan_one(planner, gear)` for every gear, in `mode.workers` forked processes, in gear order:
    what it returns comes back pickled (a job encoded for storage, engine.programs.records.Encoded,
    or the reason a gear is bad); `mode.progress(stage, done, total)` and `each_slice(outcomes)`
    as slices come back, in order (the parent stores a slice while the workers plan the next:
    issue 28, a batch's COPY was a fifth of one process's time, left serial after the planning)."""
    for gear_class in {gear.gear_class for gear in gears if gear.gear_class is not None}:
        _ready(planner, gear_class)
    size = max(1, len(gears) // (mode.workers * SLICES_PER_WORKER))
    slices = [(start, min(start + size, len(gears))) for start in range(0, len(gears), size)]
    _BATCH[:] = [planner, gears, plan_one]
    gc.freeze()   # the parent's objects out of the workers' collections: touching them would copy their pages
    try:
        return _planned_in_pool(slices, len(gears), mode, each_slice)
    finally:
        gc.unfreeze()
        _BATCH.clear()


def _planned_in_pool(slices: list[tuple[int, int]], total: int, mode: RunMode, each_slice) -> list:
    """The slices planned by `mode.workers` forked processes, in order; progress told and
    `each_slice` given each slice as it comes back (`total` gears in all)."""
    with _forked_pool(mode.workers, _in_worker) as pool:
        outcomes = []
        for planned in pool.imap(_plan_slice, slices):
            outcomes += planned
            if each_slice is not None:
                each_slice(planned)
            if mode.progress:
                mode.progress(PLANNING, len(outcomes), total)
        return outcomes


@contextlib.contextmanager
def _forked_pool(workers: int, initializer):
    """A fork Pool of `workers` processes that ignore Ctrl-C (SIGINT), terminated when the block
    ends. SIGINT is blocked while they are forked, so one arriving before a worker has set it
    ignored waits, and is then discarded there; the parent gets its own once unblocked."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        pool = multiprocessing.get_context("fork").Pool(workers, initializer=_quiet_worker, initargs=(initializer,))
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    with pool:
        yield pool


def _quiet_worker(initializer) -> None:
    """In a worker, first: Ctrl-C ignored (the parent ends the worker), then `initializer()`."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    initializer()


def _ready(planner, gear_class: str) -> None:
    """What planning a gear of the class reads from the database, read now. A refused class is
    remembered by the Planner and named by its first gear, in gear order, as in one process."""
    try:
        planner.model(gear_class)
        compiled_template(planner.template(gear_class))
    except EngineError:
        pass


class _NoDatabase:
    """A worker's connection: it shares the parent's socket, so reading anything is refused."""

    def __getattr__(self, name):
        raise EngineError("a batch worker tried to read the database (a bug: the Planner should have "
                          "read everything before the workers started)")


def _in_worker() -> None:
    _BATCH[0].conn = _NoDatabase()


def _plan_slice(bounds: tuple[int, int]) -> list:
    """In a worker: plan a slice of the gears (plan_one encodes them, here, in parallel)."""
    planner, gears, plan_one = _BATCH
    return [plan_one(planner, gear) for gear in gears[bounds[0]:bounds[1]]]


MAP_SLICES_PER_WORKER = 32   # a map's items cost alike (a program proved): the last slices short, so
                             # that no worker is left alone with a long one at the end
_MAPPED: list = []   # (work, the worker's set-up, the items) of the map being run, inherited by the forked workers


def map_in_workers(work, items: list, workers: int, in_worker=None) -> list:
    """[work(item) for item in items], in `workers` forked processes, in order. The workers inherit
    the items (each is sent only the bounds of its slice); what `work` returns comes back pickled;
    `in_worker()` runs first in each worker (to take away what it must not touch: the database
    connection it inherits). One worker, or a single item, runs here."""
    if workers <= 1 or len(items) < 2:
        return [work(item) for item in items]
    size = max(1, len(items) // (workers * MAP_SLICES_PER_WORKER))
    slices = [(start, min(start + size, len(items))) for start in range(0, len(items), size)]
    _MAPPED[:] = [work, in_worker, items]
    gc.freeze()   # the parent's objects out of the workers' collections: touching them would copy their pages
    try:
        with _forked_pool(workers, _mapping_worker) as pool:
            return [result for done in pool.imap(_map_slice, slices) for result in done]
    finally:
        gc.unfreeze()
        _MAPPED.clear()


def _mapping_worker() -> None:
    if _MAPPED[1] is not None:
        _MAPPED[1]()


def _map_slice(bounds: tuple[int, int]) -> list:
    work, _, items = _MAPPED
    return [work(item) for item in items[bounds[0]:bounds[1]]]
