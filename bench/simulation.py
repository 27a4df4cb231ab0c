"""What the simulation costs the batch: `instantiate_gears` over N generated gears (as
bench/batch.py makes them) with the real `prove` (engine.programs.verified_run: every hobbing
program simulated before it is stored) against the same call with `prove` replaced by a no-op
in this process only. Repetitions alternate; stored jobs/programs are deleted before each one.
The Jinja2 pipeline of bench/batch.py does not simulate: this ratio says how much of the gap
between the two is the proof.

    python bench/simulation.py [--count 1000] [--reps 3] [--profile] [--database-url URL]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments  # noqa: E402
from batch import FIRST_ID, clear_jobs, generate_gears, insert_gears, run_ours  # noqa: E402

from engine.programs import verified_run  # noqa: E402

WARMUP_GEARS = 100


def no_proof(lines, machine, workpiece, name) -> None:
    """The batch without the simulation (bench only)."""


def run(conn, first: int, last: int, proved: bool) -> float:
    real = verified_run.prove
    verified_run.prove = real if proved else no_proof
    try:
        seconds, _ = run_ours(conn, first, last)
    finally:
        verified_run.prove = real
    return seconds


def profile(conn, first: int, last: int, top: int) -> None:
    import cProfile
    import pstats

    clear_jobs(conn)
    profiler = cProfile.Profile()
    profiler.enable()
    run(conn, first, last, proved=True)
    profiler.disable()
    stats = pstats.Stats(profiler, stream=sys.stdout).strip_dirs()
    for order in ("cumulative", "tottime"):
        print(f"\ncProfile of instantiate_gears ({last - first + 1} gears, simulated), top {top} by {order}:")
        stats.sort_stats(order).print_stats(top)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--count", type=int, default=1_000, help="gears (default 1000)")
    parser.add_argument("--reps", type=int, default=3, help="alternated repetitions (default 3)")
    parser.add_argument("--profile", action="store_true", help="also print cProfile hotspots of a simulated run")
    parser.add_argument("--top", type=int, default=30)
    args = parse_arguments(parser, argv, smoke={"count": 20, "reps": 1})

    import psycopg

    first, last = FIRST_ID, FIRST_ID + args.count - 1
    with bench_database(args.database_url, "bench_simulation") as url, psycopg.connect(url) as conn:
        insert_gears(conn, generate_gears(first, args.count))
        for proved in (True, False):   # warm-up, untimed
            clear_jobs(conn)
            run(conn, first, min(last, first + WARMUP_GEARS - 1), proved)
        times = {True: [], False: []}
        for repetition in range(args.reps):
            for proved in ((True, False) if repetition % 2 == 0 else (False, True)):
                clear_jobs(conn)
                times[proved].append(run(conn, first, last, proved))
        if args.profile:
            profile(conn, first, last, args.top)

    with_sim, without = median(times[True]), median(times[False])
    print(f"\nsimulation: {args.count} gears, {args.reps} alternated repetitions")
    for label, proved in (("with the simulation (prove)", True), ("prove a no-op (bench only)", False)):
        print(f"  {label:30s}: median {args.count / median(times[proved]):6.0f} programs/s "
              f"({', '.join(f'{s:.2f}' for s in times[proved])} s)")
    print(f"  ratio with/without = {with_sim / without:.2f}x time; the simulation costs "
          f"{(with_sim - without) / args.count * 1e3:.2f} ms per program "
          f"({(with_sim - without) / with_sim:.0%} of the batch)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
