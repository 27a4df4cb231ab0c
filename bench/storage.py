"""Storing programs as records (issue 13): the engine's path (COPY into program_submission for a
batch, store_program for one; each program checked against its job and the stored template
version, who stored it recorded) against the path before migration 0010 (COPY and INSERT
straight into program, foreign keys only) in the same run, on the same programs. The earlier
path is rebuilt inside a transaction that is rolled back: the checking triggers switched off and
the version foreign key dropped. Runs alternate; every run is rolled back. Each program carries
the lineage line of its id (engine.nc.lineage), made before the clock starts: the timed
part is the database storing it.

    python bench/storage.py [--count 10000] [--singles 1000] [--reps 5] [--database-url URL]

Prints the medians and the ratios engine path / earlier path; it reports, it does not fail.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments  # noqa: E402

from engine.programs import storage  # noqa: E402

GEARS = (42, 43, 44, 45, 46, 47, 50, 51, 53, 54)   # the seeded gears, every hobbing class
EARLIER_COPY = ("COPY program (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace) "
                "FROM STDIN (FORMAT BINARY)")
EARLIER_INSERT = ("INSERT INTO program (job_id, gear_class, template_version, template_hash, name, lines, row_ids, "
                  "trace) VALUES (%s, %s, %s, %s, %s, %s, %s, %s) RETURNING id")
# Every trigger on program came with migration 0010 or later (the checks of 0010, 0015 and 0021).
AS_BEFORE_0010 = ("ALTER TABLE program DISABLE TRIGGER USER",
                  "ALTER TABLE program DROP CONSTRAINT program_template_version")


def planned_programs(conn) -> list:
    """One encoded program per seeded gear, with its job stored (committed)."""
    from engine.gears.records import load_gear
    from engine.programs.instantiate import Planner

    planner = Planner(conn)
    encoded = [planner.plan(load_gear(conn, gear_id)).encoded() for gear_id in GEARS]
    job_ids = storage._next_ids(conn, "job_id_seq", len(encoded))
    with conn.cursor().copy(storage.COPY_JOB) as copy:
        for job_id, item in zip(job_ids, encoded):
            copy.write_row((job_id, item.gear_id, item.gear_class, item.machine, item.hob_id,
                            storage._json(item.params), storage._json(item.module_params), storage._json(item.cutting),
                            item.work_holding_id))
    conn.commit()
    return list(zip(job_ids, encoded))


def with_lineage(conn, programs: list, ids: list[int]) -> list[tuple]:
    """The rows to store under `ids` (the programs repeated), each with the lineage line of its id."""
    lineage = storage.Lineage(conn, [item.machine for _, item in programs],
                              [(item.gear_class, item.template_version) for _, item in programs],
                              [job_id for job_id, _ in programs])
    rows = []
    for number, program_id in enumerate(ids):
        job_id, item = programs[number % len(programs)]
        lines, row_ids = lineage.added(program_id, job_id, item.machine, item.gear_class, item.template_version,
                                       item.template_hash, item.lines, item.row_ids)
        rows.append((program_id, job_id, item.gear_class, item.template_version, item.template_hash, item.name,
                     lines, row_ids, item.trace))
    return rows


def batch(conn, programs: list, count: int, statement: str) -> float:
    rows = with_lineage(conn, programs, storage._next_ids(conn, "program_id_seq", count))
    start = time.perf_counter()
    with conn.cursor().copy(statement) as copy:
        copy.set_types(storage.PROGRAM_TYPES)
        for *values, trace in rows:
            copy.write_row((*values, storage._json(trace)))
    return time.perf_counter() - start


def singles(conn, programs: list, count: int, statement: str) -> float:
    """The engine's INSERT names the program's id (drawn first, as store_one does) and whether it
    is unverified; the earlier one let the id default."""
    rows = with_lineage(conn, programs, storage._next_ids(conn, "program_id_seq", count))
    engine_path = statement == storage.INSERT_PROGRAM
    start = time.perf_counter()
    for program_id, *values, trace in rows:
        given = (program_id, *values, storage._json(trace), False) if engine_path else (*values, storage._json(trace))
        conn.execute(statement, given).fetchone()
    return time.perf_counter() - start


def timed(conn, earlier: bool, measure, *args) -> float:
    """One run, rolled back; the earlier path's schema exists only inside it."""
    for statement in AS_BEFORE_0010 if earlier else ():
        conn.execute(statement)
    try:
        return measure(conn, *args)
    finally:
        conn.rollback()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--count", type=int, default=10_000, help="programs in a batch (default 10000)")
    parser.add_argument("--singles", type=int, default=1_000, help="programs stored one by one (default 1000)")
    parser.add_argument("--reps", type=int, default=5, help="alternated repetitions (default 5)")
    args = parse_arguments(parser, argv, smoke={"count": 50, "singles": 10, "reps": 1})

    import psycopg

    runs = {"batch, engine path": (False, batch, args.count, storage.COPY_PROGRAM),
            "batch, before 0010": (True, batch, args.count, EARLIER_COPY),
            "one by one, engine path": (False, singles, args.singles, storage.INSERT_PROGRAM),
            "one by one, before 0010": (True, singles, args.singles, EARLIER_INSERT)}
    with bench_database(args.database_url, "bench_storage") as url, psycopg.connect(url) as conn:
        programs = planned_programs(conn)
        times = {name: [] for name in runs}
        for repetition in range(args.reps + 1):   # the first is an untimed warm-up
            for name in (list(runs) if repetition % 2 else list(reversed(runs))):
                earlier, measure, count, statement = runs[name]
                seconds = timed(conn, earlier, measure, programs, count, statement)
                if repetition:
                    times[name].append(seconds)
    for name, (_, _, count, _) in runs.items():
        print(f"{name:25s}: median {count / median(times[name]):7.0f} programs/s "
              f"({', '.join(f'{s:.2f}' for s in times[name])} s)")
    for kind in ("batch", "one by one"):
        ratio = median(times[f"{kind}, engine path"]) / median(times[f"{kind}, before 0010"])
        print(f"{kind}: time engine path / before 0010 = {ratio:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
