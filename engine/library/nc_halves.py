"""A long program read in two processes: the second half of its lines in a forked process while
this one reads the first (tokens, facts and the text of each row are per line, and the import
spends a third of its time on them). What the fork returns is pickled: small texts and facts,
never trees. The forked process touches no database connection and ends with os._exit (as
multiprocessing's forked workers do), so the parent's connection is never closed by it; it is
forked before the import starts any thread."""
from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

TWO_PROCESSES_FROM = 20_000   # lines: below this, forking costs more than it saves
_WORK: list = []              # the work of the import being read, inherited by the fork


def in_halves(count: int, work: Callable[[int, int], object]) -> list:
    """[work(0, count)], or [work(0, middle), work(middle, count)] with the second in a fork."""
    if count < TWO_PROCESSES_FROM:
        return [work(0, count)]
    middle = count // 2
    _WORK[:] = [work]
    try:
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:   # a dead fork
            second = pool.submit(_second, middle, count)                                  # raises, never hangs
            first = work(0, middle)
            return [first, second.result()]
    finally:
        _WORK.clear()


def _second(start: int, end: int):
    return _WORK[0](start, end)
