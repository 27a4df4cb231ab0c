"""The instantiation's budget is CPU time (issue 26): the same template is accepted or refused
whatever the machine's load. Other processes burn every core (busy loops started here, four per
core, so this thread gets a fifth of a core or less) while a template near its budget, but
under it, compiles and runs: it is accepted, five times out of five. A wall-clock budget refused
it (a busy machine made it take several times its CPU time). A template over its budget is
still refused.

No assertion reads a clock: the budgets are set from the template's own CPU time, measured
here (time.thread_time, the clock the budget reads), and the test asserts only accepted or
refused. The garbage collector is off while it runs: a collection falls in one run and not
another and would double that run's CPU time, which is the template's no more than the load is."""
import gc
import multiprocessing
import os
import time

import pytest

from engine.templates import budget
from engine.templates.decision_table import CompiledTemplate, TemplateError
from engine.templates.rows import Template, TemplateRow

ROWS = 2000   # each a little arithmetic: a run of some 50 ms of CPU, longer than a time slice


def rows() -> tuple[TemplateRow, ...]:
    return tuple(TemplateRow(10 * k + 10, "main", 1, None, f"x = sqrt(2) * i + {k}", 'f"X{x:.3f}"', None)
                 for k in range(ROWS))


def _burn(stop) -> None:
    while not stop.is_set():
        pass


@pytest.fixture
def busy_machine():
    """Four busy loops per core, until the test ends (and no garbage collection)."""
    context = multiprocessing.get_context("fork")
    stop = context.Event()
    burners = [context.Process(target=_burn, args=(stop,), daemon=True) for _ in range(4 * (os.cpu_count() or 1))]
    for burner in burners:
        burner.start()
    assert all(burner.is_alive() for burner in burners)
    gc.collect()
    gc.disable()
    yield
    gc.enable()
    stop.set()
    for burner in burners:
        burner.join(10)
        if burner.is_alive():
            burner.kill()


def cpu_seconds(work) -> float:
    """The CPU time of this thread that `work()` takes, the most of three runs after a first
    (the budget reads the same clock)."""
    work()
    spent = []
    for _ in range(3):
        start = time.thread_time()
        work()
        spent.append(time.thread_time() - start)
    return max(spent)


@pytest.fixture
def template():
    """The template compiled before the machine is busy (the next test compiles it busy)."""
    return CompiledTemplate(Template("busy", 1, rows()))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_run_under_its_cpu_budget_is_accepted_on_a_busy_machine(template, busy_machine):
    jobs = iter(range(1, 1000))   # a new job each run: no row's outcome comes from the memo
    run = cpu_seconds(lambda: template.run({"i": next(jobs)}, deadline_seconds=600))
    for _ in range(5):
        assert len(template.run({"i": next(jobs)}, deadline_seconds=2 * run).lines) == ROWS
    with pytest.raises(TemplateError, match="exceeded .* s of CPU time"):
        template.run({"i": next(jobs)}, deadline_seconds=0.3 * run)


@pytest.mark.slow   # keeps both cores busy for seconds
def test_a_compile_under_its_cpu_budget_is_accepted_on_a_busy_machine(busy_machine, monkeypatch):
    compile_time = cpu_seconds(lambda: CompiledTemplate(Template("busy", 1, rows())))
    monkeypatch.setattr(budget, "seconds_for", lambda count: 2 * compile_time)
    for _ in range(5):
        assert len(CompiledTemplate(Template("busy", 1, rows())).rows) == ROWS
    monkeypatch.setattr(budget, "seconds_for", lambda count: 0.3 * compile_time)
    with pytest.raises(TemplateError, match="compiling the template exceeded"):
        CompiledTemplate(Template("busy", 1, rows()))
