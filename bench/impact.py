"""The impact step of `engine template release` (issue 15) over N stored jobs of one seeded class
(spur), against a baseline in the same run: the same jobs read and made again with the draft (its
compiled template evaluated for each job), without the released programs read and without diffing.
A few hundred spur jobs are made by the engine (verifier and simulation); N jobs are copied from
them with their own program names (so no two jobs share their parameters) and stored with their
released programs through the batch COPY path; then a row is edited through template_view, so
every program changes and each is proved (verifier and hobbing simulation, issue 28) in
`--workers` processes (default 2). Also printed: the same impact proved in one process, so the
workers' gain is a ratio from the same run, and the CPU seconds of both (all their processes: on a
shared machine the wall time also counts what the other processes took).
Target (issues 15, 28): impact of 10,000 jobs, all changed and proved, <= 10 s with two workers
on the 2-core machine.

    python bench/impact.py [--count 10000] [--reps 3] [--workers 2] [--database-url URL]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments, verdict  # noqa: E402

TARGET_SECONDS = 10.0
FIRST_GEAR = 100_000
MADE_GEARS = 300
GEAR_CLASS = "spur"
JOBS = "SELECT id, gear_class, params, module_params FROM job WHERE gear_class = %s ORDER BY id"
EDIT = "UPDATE template_view SET o = %s WHERE gear_class = %s AND id = 1800"   # the coolant-on line


def stored_jobs(conn, count: int) -> None:
    """`count` spur jobs with their released programs, copied from jobs the engine made."""
    from batch import generate_gears, insert_gears

    from engine.programs.instantiate import instantiate_gears
    from engine.programs.records import Encoded
    from engine.programs.storage import store_many
    from engine.templates.decision_table import compiled_template
    from engine.templates.versions import released_template

    made_gears = min(MADE_GEARS, count)   # a smaller batch (--smoke) makes fewer
    insert_gears(conn, generate_gears(FIRST_GEAR, made_gears))
    instantiate_gears(conn, FIRST_GEAR, FIRST_GEAR + made_gears - 1)
    conn.commit()
    made = conn.execute("SELECT gear_id, machine, hob_id, params, module_params FROM job WHERE gear_class = %s",
                        (GEAR_CLASS,)).fetchall()
    released = compiled_template(released_template(conn, GEAR_CLASS))
    encoded = []
    for number in range(count - len(made)):
        gear_id, machine, hob_id, params, modules = made[number % len(made)]
        params = {**params, "program_name": f"BENCH{number:05d}"}
        result = released.run(params, modules)
        encoded.append(Encoded(gear_id, GEAR_CLASS, machine, hob_id, json.dumps(params), json.dumps(modules), "{}",
                               released.template.version, released.template.hash, params["program_name"],
                               result.lines, result.row_ids, "{}"))
    if encoded:
        store_many(conn, encoded)
    conn.commit()


def cpu_seconds() -> float:
    """CPU seconds of this process and of its workers that ended (user and system): on a shared
    machine the wall time says how busy the other processes were, this what the run itself spent."""
    spent = os.times()
    return spent.user + spent.system + spent.children_user + spent.children_system


def run_impact(conn, workers: int) -> tuple[float, int, float]:
    from engine.release.impact import impact
    from engine.templates import decision_table

    decision_table._CACHE.clear()   # as a new process: nothing compiled, nothing remembered
    start, cpu = time.perf_counter(), cpu_seconds()
    report = impact(conn, GEAR_CLASS, workers)
    conn.rollback()
    return time.perf_counter() - start, report.changed, cpu_seconds() - cpu


def run_bare(conn, workers: int) -> tuple[float, int, float]:
    """The same jobs read and made again with the draft: no released program, no diff."""
    from engine.templates import decision_table
    from engine.templates.decision_table import compiled_template
    from engine.templates.versions import draft_template

    decision_table._CACHE.clear()
    start, cpu = time.perf_counter(), cpu_seconds()
    draft = compiled_template(draft_template(conn, GEAR_CLASS))
    lines = sum(len(draft.run(params, modules).lines) for _, _, params, modules in conn.execute(JOBS, (GEAR_CLASS,)))
    conn.rollback()
    return time.perf_counter() - start, lines, cpu_seconds() - cpu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--count", type=int, default=10_000, help="stored jobs of the class (default 10000)")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each (default 3)")
    parser.add_argument("--workers", type=int, default=2, help="processes proving the changed programs (default 2)")
    args = parse_arguments(parser, argv, smoke={"count": 40, "reps": 1})

    import psycopg

    with bench_database(args.database_url, "bench_impact") as url, psycopg.connect(url) as conn:
        stored_jobs(conn, args.count)
        conn.execute(EDIT, ('"M8 ; COOLANT ON"', GEAR_CLASS))
        conn.commit()
        jobs = conn.execute("SELECT count(*) FROM job WHERE gear_class = %s", (GEAR_CLASS,)).fetchone()[0]
        runs = {"impact": (run_impact, args.workers), "one": (run_impact, 1), "bare": (run_bare, 1)}
        times, counts, cpu = {name: [] for name in runs}, {}, {name: [] for name in runs}
        for repetition in range(args.reps):
            for name in (runs if repetition % 2 == 0 else reversed(list(runs))):
                seconds, counts[name], spent = runs[name][0](conn, runs[name][1])
                times[name].append(seconds)
                cpu[name].append(spent)
    ours, one, bare = median(times["impact"]), median(times["one"]), median(times["bare"])
    print(f"impact: {jobs} stored {GEAR_CLASS} jobs, {counts['impact']} programs change, {args.reps} alternated runs")
    print(f"impact, {args.workers} workers (read, evaluate, compare, prove, diff): median {ours:6.2f} s = "
          f"{jobs / ours:6.0f} jobs/s")
    print(f"impact, one process                             : median {one:6.2f} s = {jobs / one:6.0f} jobs/s")
    print(f"bare (read, evaluate the draft)                 : median {bare:6.2f} s = {jobs / bare:6.0f} jobs/s")
    print(f"CPU seconds (all processes): {args.workers} workers median {median(cpu['impact']):6.2f} s, "
          f"one process median {median(cpu['one']):6.2f} s")
    print(f"workers' gain {one / ours:.2f}x; ratio impact/bare = {ours / bare:.2f}x; impact {ours:.2f} s "
          f"(target <= {TARGET_SECONDS:g} s): {verdict(ours <= TARGET_SECONDS)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
