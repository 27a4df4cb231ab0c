"""The evaluator: asteval (this tree) against the compiled code objects it replaced (an earlier
commit, default 6710955, the last before the switch), on the same template rows with the same
job parameters, in the same run. The jobs of N generated gears (spur and helical, as
bench/batch.py makes them) are planned once by this tree's model and written to a file; each
tree then loads that file in a subprocess of its own (same interpreter, its own source tree
first on sys.path), compiles the templates once and times evaluating every job. Runs alternate.

Printed: compiled (before), asteval with every row evaluated (memo off), asteval as the engine
runs it (a row whose inputs repeat an earlier job's takes its outcome from the memo), and the
ratios. No target: the issue asks for the cost to be measured and recovered where the time goes.

    python bench/evaluator.py [--count 2000] [--reps 3] [--against REV] [--database-url URL]
"""
from __future__ import annotations

import argparse
import json
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

from msgspec.structs import astuple

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, median, parse_arguments  # noqa: E402
from latency import source_tree_of  # noqa: E402

AGAINST = "6710955"   # main just before asteval became the evaluator (issue 12)
FIRST_ID = 100_000

# Runs in the subprocess: the tree's own engine evaluates every job; prints seconds as JSON.
TIMER = r"""
import json, pickle, sys, time
tree, data, memo = sys.argv[1], sys.argv[2], sys.argv[3] == "memo"
sys.path.insert(0, tree)
import engine.templates.decision_table as table
from engine.templates.rows import Template, TemplateRow
assert table.__file__.startswith(tree), table.__file__
with open(data, "rb") as file:
    templates, jobs = pickle.load(file)
compiled = {name: table.compiled_template(Template(name, version, tuple(TemplateRow(*row) for row in rows)))
            for name, (version, rows) in templates.items()}
if not memo and hasattr(table.CompiledTemplate, "remembered"):
    table.CompiledTemplate.remembered = lambda self, key: None
lines = 0
start = time.perf_counter()
for gear_class, params, module_params in jobs:
    lines += len(compiled[gear_class].run(params, module_params).lines)
print(json.dumps({"seconds": time.perf_counter() - start, "lines": lines}))
"""


def planned_jobs(url: str, count: int) -> tuple[dict, list]:
    """The templates' rows and every gear's job parameters, as this tree's Planner makes them."""
    import psycopg
    from batch import generate_gears, insert_gears

    from engine.programs.instantiate import Planner
    from engine.programs.records import Planned

    with psycopg.connect(url) as conn:
        insert_gears(conn, generate_gears(FIRST_ID, count))
        planner = Planner(conn)
        from engine.gears.records import load_gears

        planned: list[Planned] = [planner.plan(gear) for gear in load_gears(conn, FIRST_ID, FIRST_ID + count - 1)]
        conn.rollback()
    templates = {item.gear_class: (item.template.version, [astuple(row) for row in item.template.rows])
                 for item in planned}
    return templates, [(item.gear_class, item.params, item.module_params) for item in planned]


def timed(tree: Path, data: Path, memo: bool) -> dict:
    done = subprocess.run([sys.executable, "-c", TIMER, str(tree), str(data), "memo" if memo else "all"],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"evaluator run in {tree} failed: {done.stderr.strip()[-800:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--count", type=int, default=2000, help="gears whose jobs are evaluated (default 2000)")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each (default 3)")
    parser.add_argument("--against", default=AGAINST, metavar="REV",
                        help=f"the compiled evaluator's commit ({AGAINST})")
    args = parse_arguments(parser, argv, smoke={"count": 20, "reps": 1})
    with bench_database(args.database_url, "bench_evaluator") as url, tempfile.TemporaryDirectory() as folder:
        data = Path(folder) / "jobs.pickle"
        data.write_bytes(pickle.dumps(planned_jobs(url, args.count)))
        (Path(folder) / "before").mkdir()
        before = source_tree_of(args.against, Path(folder) / "before")
        if before is None:
            sys.exit(f"bench/evaluator.py: this checkout has no commit {args.against}; give --against REV")
        runs = {"compiled": (before, False), "asteval, memo off": (REPO, False), "asteval (engine)": (REPO, True)}
        times = {name: [] for name in runs}
        lines = {}
        for _ in range(args.reps):
            for name, (tree, memo) in runs.items():
                result = timed(tree, data, memo)
                times[name].append(result["seconds"])
                lines[name] = result["lines"]
    if len(set(lines.values())) != 1:
        print(f"the evaluators emitted different line counts: {lines}")
        return 1
    base = median(times["compiled"])
    print(f"evaluator: {args.count} jobs (spur and helical), {args.reps} alternated runs, {lines['compiled']} lines")
    for name in runs:
        seconds = median(times[name])
        print(f"{name:20}: median {seconds * 1000:8.1f} ms = {seconds / args.count * 1e6:6.1f} us/job, "
              f"{seconds / base:5.2f}x compiled ({args.against})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
