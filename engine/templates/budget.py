"""What one instantiation may spend: CPU time and the bytes of the values its expressions build
(design notes §4). A shop runs thousands of gears unattended, so no template row, however
written, may hold a batch up or take the machine's memory.

Time is the CPU time of the thread doing the work (issue 26): on a busy machine the same
template must be accepted or refused, and wall-clock time would refuse a valid template, and
blame one of its rows, whenever other work took the cores. It is the thread's time, not the
process's: an import proves its rows in a thread while the importing thread spends its own CPU
on the database (engine.library.nc_verify), and runners may share a process. There is no
wall-clock backstop: an expression can call no function that blocks (the gate's whitelist,
engine.templates.functions), so the only way a run can last is by computing, which this counts.

Each guard (engine.templates.guards), f-string field, slice and nc_path block pays for the value
it builds, temporaries included, as it builds it: the run is refused once it has built more than
MAX_BYTES, and at the first payment after its deadline. Nothing an expression does between two
payments costs more than one value of the guards' MAX_SIZE, so neither bound can be overrun by
more than that, whatever one expression holds. The running budget is the thread's own (runners
may share a process), and there is none between runs.
"""
from __future__ import annotations

import sys
import threading
import time

MAX_SECONDS = 2.0            # CPU time (of its thread) of one instantiation
SECONDS_PER_ROW = 50e-6      # and per row of its template: an imported program of 100,000 lines is
                             # 100,000 rows, about 20 us each to evaluate (asteval, trace, memo)
MAX_BYTES = 64 << 20         # bytes of the values one instantiation's expressions build


def compiling(rows: int) -> spending:
    """`with compiling(rows):` the compile of a template of `rows` rows (the gate's evaluation of
    constant parts included) within the time its run has: no template, however written, holds
    an import, lint or a batch up before it runs."""
    return spending(Budget(seconds_for(rows), what="compiling the template"))


def seconds_for(rows: int) -> float:
    """The time of an instantiation of a template of `rows` rows (2.002 s for 40 rows, 7 s for 100,000)."""
    return MAX_SECONDS + SECONDS_PER_ROW * rows


class Budget:
    """The CPU time and bytes left to one instantiation, spent by the thread that makes it.

    `deadline` is in the thread's CPU time (time.thread_time). Reading that clock is a system
    call (about ten times perf_counter's cost, and payments are many), so it is read only when
    the wall clock says the deadline could have passed: a thread's CPU time never advances
    faster than wall time, so until `wall_next` (perf_counter) at least `left` CPU seconds remain."""
    __slots__ = ("seconds", "deadline", "wall_next", "max_bytes", "bytes_left", "what")

    def __init__(self, seconds: float = MAX_SECONDS, max_bytes: int = MAX_BYTES, what: str = "instantiation"):
        self.seconds, self.deadline, self.what = seconds, time.thread_time() + seconds, what
        self.wall_next = time.perf_counter() + seconds
        self.max_bytes = self.bytes_left = max_bytes

    @classmethod
    def within(cls, outer: Budget | None) -> Budget:
        """Bytes of its own, and a deadline no later than `outer`'s (the gate's evaluation of a
        constant part, while a whole template is compiled)."""
        budget = cls()
        if outer is not None and outer.deadline < budget.deadline:
            budget.seconds, budget.deadline, budget.what = outer.seconds, outer.deadline, outer.what
            budget.wall_next = outer.wall_next
        return budget

    def pay(self, nbytes: int) -> None:
        self.bytes_left -= nbytes
        if self.bytes_left < 0:
            raise ValueError(f"the expressions built more than {self.max_bytes >> 20} MiB in one instantiation")
        self.check_time()

    def check_time(self) -> None:
        if time.perf_counter() < self.wall_next:
            return   # less wall time has passed than CPU time was left: none can be spent yet
        left = self.deadline - time.thread_time()
        if left < 0:
            raise TimeoutError(f"{self.what} exceeded {self.seconds:.3g} s of CPU time")
        self.wall_next = time.perf_counter() + left

    @property
    def spent(self) -> int:
        """Bytes paid so far (a remembered row outcome pays again what it cost the first time)."""
        return self.max_bytes - self.bytes_left


_THREAD = threading.local()


def running() -> Budget | None:
    return getattr(_THREAD, "budget", None)


class spending:
    """`with spending(budget):` makes `budget` the one that built values pay from."""

    def __init__(self, budget: Budget):
        self.budget = budget

    def __enter__(self) -> Budget:
        self.outer, _THREAD.budget = running(), self.budget
        return self.budget

    def __exit__(self, *exc) -> None:
        _THREAD.budget = self.outer


def paid(value):
    """`value`, its size in bytes paid from the running budget (none between runs)."""
    budget = getattr(_THREAD, "budget", None)
    if budget is not None:
        budget.pay(sys.getsizeof(value))
    return value


def pay_time() -> None:
    """The deadline, checked where work happens without building (nc_path between blocks)."""
    budget = getattr(_THREAD, "budget", None)
    if budget is not None:
        budget.check_time()
