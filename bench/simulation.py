"""What the simulation costs the batch: `instantiate_gears` over N generated gears (as
bench/batch.py makes them) with the real `prove` (engine.programs.verified_run: every hobbing
program simulated before it is stored) against the same call with `prove` replaced by a no-op
in this process only. Repetitions alternate; stored jobs/programs are deleted before each one.
The Jinja2 pipeline of bench/batch.py does not simulate: this ratio says how much of the gap
between the two is the proof.

Then the simulation alone against an earlier tree (issue 28): every program the batch proved
is simulated again by this tree and by `--against` (default 7bb4197, main before issue 28:
the golden-section search), each in a subprocess of its own (the same interpreter, its source
tree first on sys.path), runs alternated; printed per program and as a ratio, with how many
of the two trees' reports (Report.lines(): findings, cuts, times) differ.

    python bench/simulation.py [--count 1000] [--reps 3] [--against REV] [--profile] [--database-url URL]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments  # noqa: E402
from batch import FIRST_ID, clear_jobs, generate_gears, insert_gears, run_ours  # noqa: E402
from latency import source_tree_of  # noqa: E402

from engine.programs import verified_run  # noqa: E402

WARMUP_GEARS = 100
AGAINST = "7bb4197"      # main before issue 28: the golden-section search, every section with numpy
WARMUP_PROGRAMS = 50     # simulated untimed first in each subprocess (imports, the switch to numpy)

# Runs in the subprocess: the tree's own simulation follows every program; prints seconds and reports.
# The records (gear, hob, machine) travel as plain data (plain_records) and are rebuilt from the
# tree's own classes with the fields that tree knows: a pickle of this tree's records names classes
# and fields an earlier tree lacks (a Struct, the material's cutting speeds).
TIMER = r"""
import dataclasses, importlib, json, pickle, sys, time
tree, data = sys.argv[1], sys.argv[2]
sys.path.insert(0, tree)
from engine.simulation.hobbing.run import simulate_program
import engine.simulation.hobbing.run as run
assert run.__file__.startswith(tree), run.__file__

def built(value):
    if isinstance(value, dict) and "__record__" in value:
        module, _, name = value["__record__"].rpartition(".")
        kind = getattr(importlib.import_module(module), name)
        known = getattr(kind, "__struct_fields__", None) or [field.name for field in dataclasses.fields(kind)]
        return kind(**{key: built(item) for key, item in value["fields"].items() if key in known})
    if isinstance(value, (list, tuple)):
        return type(value)(built(item) for item in value)
    return value

with open(data, "rb") as file:
    programs, warmup = pickle.load(file)
programs = [built(program) for program in programs]
for lines, gear, hob, machine, name in programs[:warmup]:
    simulate_program(lines, gear, hob, machine, name)
start = time.perf_counter()
reports = [simulate_program(lines, gear, hob, machine, name) for lines, gear, hob, machine, name in programs]
seconds = time.perf_counter() - start
print(json.dumps({"seconds": seconds, "reports": [report.lines() for report in reports]}))
"""


def plain_records(value):
    """A record (Struct or dataclass) as {"__record__": its class, "fields": its fields}, nested
    records and sequences too; anything else as it is."""
    names = getattr(value, "__struct_fields__", None)
    if names is None and dataclasses.is_dataclass(value) and not isinstance(value, type):
        names = [field.name for field in dataclasses.fields(value)]
    if names is not None:
        return {"__record__": f"{type(value).__module__}.{type(value).__qualname__}",
                "fields": {name: plain_records(getattr(value, name)) for name in names}}
    if isinstance(value, (list, tuple)):
        return type(value)(plain_records(item) for item in value)
    return value


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


def proved_programs(conn, first: int, last: int) -> list:
    """(lines, gear, hob, machine, name) of every program the batch proves, recorded from one run."""
    real, recorded = verified_run.prove, []

    def recording(lines, machine, workpiece, name) -> None:
        recorded.append((list(lines), workpiece.gear, workpiece.hob, machine, name))
        real(lines, machine, workpiece, name)

    verified_run.prove = recording
    try:
        clear_jobs(conn)
        run_ours(conn, first, last)
    finally:
        verified_run.prove = real
    return recorded


def timed_tree(tree: Path, data: Path) -> dict:
    done = subprocess.run([sys.executable, "-c", TIMER, str(tree), str(data)], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"simulation run in {tree} failed: {done.stderr.strip()[-800:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def compare_trees(programs: list, against: str, reps: int) -> None:
    """The same programs simulated by this tree and by `against`, alternated; ratio and report differences."""
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "before").mkdir()
        before = source_tree_of(against, Path(folder) / "before")
        if before is None:
            print(f"\nsimulation alone: this checkout has no commit {against}; give --against REV")
            return
        data = Path(folder) / "programs.pickle"
        data.write_bytes(pickle.dumps((plain_records(programs), min(WARMUP_PROGRAMS, len(programs)))))
        trees = {"this tree": HERE.parent, against: before}
        runs: dict = {name: [] for name in trees}
        for repetition in range(reps):
            for name in (list(trees) if repetition % 2 == 0 else list(trees)[::-1]):
                runs[name].append(timed_tree(trees[name], data))
    times = {name: [found["seconds"] for found in runs[name]] for name in trees}
    seconds = {name: median(times[name]) for name in trees}
    ours, theirs = runs["this tree"][0]["reports"], runs[against][0]["reports"]
    differing = sum(mine != other for mine, other in zip(ours, theirs))
    print(f"\nsimulation alone: {len(programs)} proved programs, {reps} alternated runs per tree (subprocesses)")
    for name in trees:
        print(f"  {name:12s}: median {seconds[name] / len(programs) * 1e3:6.2f} ms per program "
              f"({', '.join(f'{value:.2f}' for value in times[name])} s)")
    print(f"  ratio {against}/this tree = {seconds[against] / seconds['this tree']:.2f}x faster (target >= 3); "
          f"reports differing: {differing} of {len(programs)}")


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
    parser.add_argument("--against", default=AGAINST, metavar="REV",
                        help=f"the tree the simulation alone is compared with (default {AGAINST})")
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
        programs = proved_programs(conn, first, last)
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
    compare_trees(programs, args.against, args.reps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
