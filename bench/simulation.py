"""What the simulation costs the batch: `instantiate_gears` over N generated gears (as
bench/batch.py makes them) with the real `prove` (engine.programs.verified_run: every hobbing
program simulated before it is stored) against the same call with `prove` replaced by a no-op
in this process only. Repetitions alternate; stored jobs/programs are deleted before each one.
The Jinja2 pipeline of bench/batch.py does not simulate: this ratio says how much of the gap
between the two is the proof.

Then the simulation alone against an earlier tree (issue 28): every program the batch proved
is simulated again by `--against` (default 7bb4197, main before issue 28: the golden-section
search, every section with numpy), the baseline, and by this tree along each of its two paths:
plain floats (engine.simulation.hobbing.contact.MATH_SECTIONS never reached) and numpy (forced
from the first section). Each run is a subprocess of its own (the same interpreter, its source
tree first on sys.path), the three alternated; printed per program, per section (the plain
path's count) and as ratios against the baseline, with how many reports (Report.lines():
findings, cuts, times) differ from the baseline's and between the two paths. Last, what
importing numpy costs a fresh process, and the break-even that sets MATH_SECTIONS: that cost
over what numpy saves per section.

    python bench/simulation.py [--count 1000] [--reps 3] [--against REV] [--import-runs 11]
                               [--profile] [--database-url URL]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import pickle
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments  # noqa: E402
from batch import FIRST_ID, clear_jobs, generate_gears, insert_gears, run_ours  # noqa: E402
from latency import source_tree_of  # noqa: E402

from engine.programs import verified_run  # noqa: E402

WARMUP_GEARS = 100
AGAINST = "7bb4197"      # main before issue 28: the golden-section search, every section with numpy
WARMUP_PROGRAMS = 50     # simulated untimed first in each subprocess (imports, the caches; numpy if forced)
IMPORT_RUNS = 11         # alternated fresh-process starts with and without `import numpy`
PATHS = {"plain": "plain floats", "numpy": "numpy forced"}   # this tree's two paths (TIMER's modes)

# Runs in the subprocess: the tree's own simulation follows every program; prints seconds (wall and
# CPU), the sections the plain path counted and the reports. Mode "plain" puts contact.MATH_SECTIONS
# out of reach (no numpy is imported, which is checked), "numpy" below the first section, "as is"
# leaves the tree alone (the baseline). The records (gear, hob, machine) travel as plain data
# (plain_records) and are rebuilt from the tree's own classes with the fields that tree knows: a
# pickle of this tree's records names classes and fields an earlier tree lacks (a Struct, the
# material's cutting speeds).
TIMER = r"""
import dataclasses, importlib, json, math, pickle, sys, time
tree, data, mode = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, tree)
from engine.simulation.hobbing.run import simulate_program
import engine.simulation.hobbing.run as run
assert run.__file__.startswith(tree), run.__file__
threshold = None
if mode != "as is":
    from engine.simulation.hobbing import contact
    threshold = contact.MATH_SECTIONS
    contact.MATH_SECTIONS = math.inf if mode == "plain" else -1

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
counted = contact._followed[0] if mode == "plain" else None
start, cpu = time.perf_counter(), time.process_time()
reports = [simulate_program(lines, gear, hob, machine, name) for lines, gear, hob, machine, name in programs]
seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
assert mode != "plain" or "numpy" not in sys.modules, "the plain path imported numpy"
sections = contact._followed[0] - counted if mode == "plain" else None
print(json.dumps({"seconds": seconds, "cpu": cpu, "sections": sections, "threshold": threshold,
                  "reports": [report.lines() for report in reports]}))
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


def timed_tree(tree: Path, mode: str, data: Path) -> dict:
    done = subprocess.run([sys.executable, "-c", TIMER, str(tree), str(data), mode], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"simulation run in {tree} ({mode}) failed: {done.stderr.strip()[-800:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def compare_trees(programs: list, against: str, reps: int) -> dict:
    """The same programs simulated by `against` (the baseline, as that tree runs them) and by this
    tree's two paths, alternated, the order turned by one each repetition; printed with ratios and
    report differences. Returns each path's runs (TIMER's output), the baseline's if it was there."""
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "before").mkdir()
        before = source_tree_of(against, Path(folder) / "before")
        if before is None:
            print(f"\nsimulation alone: this checkout has no commit {against} (give --against REV); "
                  "this tree's two paths only")
        data = Path(folder) / "programs.pickle"
        data.write_bytes(pickle.dumps((plain_records(programs), min(WARMUP_PROGRAMS, len(programs)))))
        kinds = {label: (HERE.parent, mode) for mode, label in PATHS.items()}
        if before is not None:
            kinds = {against: (before, "as is"), **kinds}
        runs = alternated(kinds, data, reps)
    print_paths(runs, against if before is not None else None, len(programs), reps)
    return runs


def alternated(kinds: dict, data: Path, reps: int) -> dict:
    """{name: [TIMER's output per repetition]} for kinds {name: (tree, mode)}, run in turn."""
    runs: dict = {name: [] for name in kinds}
    names = list(kinds)
    for repetition in range(reps):
        turn = repetition % len(names)
        for name in names[turn:] + names[:turn]:
            runs[name].append(timed_tree(*kinds[name], data))
    return runs


def print_paths(runs: dict, baseline: str | None, count: int, reps: int) -> None:
    """Per program (wall and CPU), per section of the plain path's count, ratios to the baseline."""
    plain, fast = PATHS["plain"], PATHS["numpy"]
    sections = runs[plain][0]["sections"]
    print(f"\nsimulation alone: {count} proved programs, {sections / count:,.0f} sections each (the plain "
          f"path's count); runs of each: {reps}, alternated (subprocesses); medians, wall (CPU):")
    for name, found in runs.items():
        wall, cpu = seconds_of(found)
        each = ", ".join(f"{one['seconds']:.2f}" for one in found)
        print(f"  {name:14s}: {wall / count * 1e3:6.2f} ms ({cpu / count * 1e3:6.2f}) per program, "
              f"{wall / sections * 1e6:5.2f} µs ({cpu / sections * 1e6:5.2f}) per section "
              f"({each} s)")
    if baseline is not None:
        for name, target in ((plain, "one gear's path, no target"), (fast, "a batch's path, target >= 3")):
            print(f"  ratio {baseline}/{name} = {ratio(runs[baseline], runs[name])} faster ({target}); "
                  f"reports differing: {differing(runs[name], runs[baseline])} of {count}")
    print(f"  ratio {plain}/{fast} = {ratio(runs[plain], runs[fast])} time; "
          f"reports differing: {differing(runs[plain], runs[fast])} of {count}")


def seconds_of(found: list) -> tuple[float, float]:
    """Median wall and CPU seconds of one kind's runs."""
    return median(one["seconds"] for one in found), median(one["cpu"] for one in found)


def ratio(slow: list, fast: list) -> str:
    """The two kinds' median times as a ratio, wall (CPU)."""
    (slow_wall, slow_cpu), (fast_wall, fast_cpu) = seconds_of(slow), seconds_of(fast)
    return f"{slow_wall / fast_wall:.2f}x ({slow_cpu / fast_cpu:.2f}x)"


def differing(ours: list, theirs: list) -> int:
    """Programs whose reports differ between the first runs of two kinds."""
    return sum(mine != other for mine, other in zip(ours[0]["reports"], theirs[0]["reports"]))


def numpy_import(runs: int) -> tuple[float, float]:
    """Seconds (wall, CPU) importing numpy adds to a fresh process: the medians of `python -c
    "import numpy"` less those of `python -c pass`, alternated after one untimed start of each."""
    codes = {"pass": "pass", "numpy": "import numpy"}
    for code in codes.values():
        started(code)
    times: dict = {name: [] for name in codes}
    for run_number in range(runs):
        for name in (list(codes) if run_number % 2 == 0 else list(codes)[::-1]):
            times[name].append(started(codes[name]))
    wall, cpu = (median(one[k] for one in times["numpy"]) - median(one[k] for one in times["pass"]) for k in (0, 1))
    return wall, cpu


def started(code: str) -> tuple[float, float]:
    """Wall and CPU (the child's user and system) seconds of `python -c code`."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    wall, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def print_break_even(runs: dict, import_runs: int, threshold) -> None:
    """The sections a process must follow for numpy's import to pay: its cost over the time numpy
    saves per section (this run's medians), against the tree's contact.MATH_SECTIONS."""
    plain, fast = runs[PATHS["plain"]], runs[PATHS["numpy"]]
    sections, costs = plain[0]["sections"], numpy_import(import_runs)
    print(f"\nimporting numpy in a fresh process: {costs[0] * 1e3:.0f} ms wall, {costs[1] * 1e3:.0f} ms CPU "
          f"(medians of {import_runs} alternated starts, less `python -c pass`)")
    for label, k, cost in (("wall", 0, costs[0]), ("CPU", 1, costs[1])):
        saved = (seconds_of(plain)[k] - seconds_of(fast)[k]) / sections
        if saved <= 0:
            print(f"  {label}: numpy saved nothing per section in this run; no break-even")
            continue
        print(f"  {label}: numpy saves {saved * 1e6:.2f} µs per section; break-even {cost * 1e3:.0f} ms / "
              f"{saved * 1e6:.2f} µs = {cost / saved:,.0f} sections (contact.MATH_SECTIONS = {threshold:,})")


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
    parser.add_argument("--import-runs", type=int, default=IMPORT_RUNS,
                        help=f"alternated fresh starts timing numpy's import (default {IMPORT_RUNS})")
    args = parse_arguments(parser, argv, smoke={"count": 20, "reps": 1, "import_runs": 1})

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
    runs = compare_trees(programs, args.against, args.reps)
    print_break_even(runs, args.import_runs, runs[PATHS["plain"]][0]["threshold"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
