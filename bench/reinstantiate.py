"""Re-instantiating stored jobs: `instantiate_jobs` (the library path behind `engine instantiate
--jobs`, template rows only, no model) over N stored jobs, against a bare baseline in the same
run: the same jobs read with the same query, the same checked template rows evaluated by a plain
asteval Interpreter in row order (no trace, no memo, no machine check), and the programs stored
with the same COPY statement. Runs alternate; programs are deleted before each.
Target (issue 12): ours <= 1.5x the baseline.

    python bench/reinstantiate.py [--count 10000] [--reps 3] [--database-url URL]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, delete_programs, median, parse_arguments, verdict  # noqa: E402

TARGET_RATIO = 1.5
FIRST_ID = 100_000
JOBS = "SELECT id, gear_id, gear_class, machine, hob_id, params, module_params FROM job ORDER BY id"


def clear_programs(conn) -> None:
    delete_programs(conn)
    conn.commit()


def run_ours(conn) -> tuple[float, int]:
    from engine.programs.remake import instantiate_jobs
    from engine.templates import decision_table

    decision_table._CACHE.clear()    # as a new process: nothing compiled, nothing remembered
    start = time.perf_counter()
    batch = instantiate_jobs(conn)
    conn.commit()
    return time.perf_counter() - start, batch.lines


def run_bare(conn) -> tuple[float, int]:
    """The same rows evaluated by asteval alone, and a COPY of the programs."""
    from engine.templates.decision_table import CompiledTemplate
    from engine.templates.evaluator import Evaluator
    from engine.templates.store import load_template

    start = time.perf_counter()
    jobs = conn.execute(JOBS).fetchall()
    compiled = {name: CompiledTemplate(load_template(conn, name)) for name in {job[2] for job in jobs}}
    evaluator = Evaluator()
    programs = [(job[0], job[3], compiled[job[2]], *bare_program(compiled[job[2]], evaluator, job[5], job[6]))
                for job in jobs]
    stored = store_bare(conn, programs)
    conn.commit()
    return time.perf_counter() - start, stored


def store_bare(conn, programs: list[tuple]) -> int:
    """COPY the programs as the engine does, each with its lineage line (engine.nc.lineage:
    the database refuses a program without one); the number of lines stored."""
    from engine.programs.storage import COPY_PROGRAM, PROGRAM_TYPES, Lineage, _next_ids

    stored = 0
    with conn.transaction():
        ids = _next_ids(conn, "program_id_seq", len(programs))
        lineage = Lineage(conn, [p[1] for p in programs], [(p[2].template.gear_class, p[2].template.version)
                                                          for p in programs], [p[0] for p in programs])
        with conn.cursor().copy(COPY_PROGRAM) as copy:
            copy.set_types(PROGRAM_TYPES)
            for program_id, (job_id, machine, template, lines, row_ids) in zip(ids, programs):
                gear_class, version, template_hash = (template.template.gear_class, template.template.version,
                                                      template.template.hash)
                lines, row_ids = lineage.added(program_id, job_id, machine, gear_class, version, template_hash,
                                               lines, row_ids)
                copy.write_row((program_id, job_id, gear_class, version, template_hash, "BARE", lines, row_ids, None))
                stored += len(lines)
    return stored


def bare_program(template, evaluator, params: dict, module_params: dict) -> tuple[list, list]:
    """Design notes §4 in a few lines: scope = job ∪ module (T, N) ∪ intermediates."""
    lines, row_ids, intermediates, module, scope = [], [], {}, None, {}
    for row in template.rows:
        if row.module != module:
            module = row.module
            scope = {**params, **module_params.get(f"{module[0]}:{module[1]}", {}), **intermediates,
                     **template.symbols, "template_version": template.template.version}

        def value(expression, scope=scope):   # this row's scope, bound now (called within the row)
            return evaluator.evaluate(expression.tree, expression.text, scope)
        if row.s:
            if row.p_calc is not None and not value(row.p_calc):
                continue
            for name, expression in row.s:
                scope[name] = intermediates[name] = value(expression)
        if row.o is not None:
            line = value(row.o)
            if row.p_emit is None or value(row.p_emit):
                lines.append(line)
                row_ids.append(row.row.id)
    return lines, row_ids


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--count", type=int, default=10_000, help="stored jobs made again (default 10000)")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each (default 3)")
    args = parse_arguments(parser, argv, smoke={"count": 20, "reps": 1})

    import psycopg
    from batch import generate_gears, insert_gears

    from engine.programs.instantiate import instantiate_gears

    with bench_database(args.database_url, "bench_reinstantiate") as url, psycopg.connect(url) as conn:
        insert_gears(conn, generate_gears(FIRST_ID, args.count))
        instantiate_gears(conn, FIRST_ID, FIRST_ID + args.count - 1)
        conn.commit()
        runs = {"ours": run_ours, "bare": run_bare}
        times, lines = {name: [] for name in runs}, {}
        for repetition in range(args.reps):
            for name in (runs if repetition % 2 == 0 else reversed(list(runs))):
                clear_programs(conn)
                seconds, lines[name] = runs[name](conn)
                times[name].append(seconds)
    if lines["ours"] != lines["bare"]:
        print(f"the two paths emitted different line counts: {lines}")
        return 1
    ours, bare = median(times["ours"]), median(times["bare"])
    print(f"reinstantiate: {args.count} stored jobs (spur and helical), {args.reps} alternated runs, "
          f"{lines['ours']} lines")
    print(f"ours: instantiate_jobs + commit            : median {ours:6.2f} s = {args.count / ours:5.0f} jobs/s")
    print(f"bare: asteval over the same rows + COPY    : median {bare:6.2f} s = {args.count / bare:5.0f} jobs/s")
    print(f"ratio ours/bare = {ours / bare:.2f}x (target <= {TARGET_RATIO}x): {verdict(ours / bare <= TARGET_RATIO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
