"""Batch CPU per program against an earlier commit (issue 28: "batch of 10,000 gears >= 2x today's
programs per CPU second"). Each tree, this one and `--against REV` (default 38b5a9c, main when
issue 28 was filed), runs in a process of its own from its own source (engine/, migrations/,
schema/, seed_templates/, bench/ of that commit): it makes its own database with its own
migrations and seed, inserts the same gears (bench/batch.py's generate_gears, the same seed), and
times `instantiate_gears` over them, as bench/batch.py's run_ours does (no compiled template
remembered, programs stored). The two trees alternate, rep by rep, so both see the same machine.

Reported per tree: programs per CPU second of the engine's process (time.process_time: the
planning, evaluation, verification and simulation; the server's own CPU is not in it), and per
wall second. Target: this tree >= 2x the earlier commit per CPU second.

    python bench/batch_against.py [--against REV] [--count 10000] [--reps 3] [--database-url URL]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, median, parse_arguments, verdict  # noqa: E402

TARGET_RATIO = 2.0
BASELINE = "38b5a9c"        # main on 2026-11-28, when issue 28 was filed
FOLDERS = ("engine", "migrations", "schema", "seed_templates", "bench", "pyproject.toml")   # a checkout: engine.paths

# Run inside the tree given as argv[1]: its engine and its bench helpers, nothing of this checkout.
DRIVER = """
import json, sys, time
tree, url, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
sys.path[:0] = [tree, tree + '/bench']
import psycopg
from _common import bench_database
from batch import FIRST_ID, generate_gears, insert_gears, clear_jobs
import engine
assert engine.__file__.startswith(tree), engine.__file__
from engine.programs.instantiate import instantiate_gears
from engine.programs.options import RunMode
from engine.templates import decision_table
with bench_database(url, 'bench_against') as db, psycopg.connect(db) as conn:
    insert_gears(conn, generate_gears(FIRST_ID, count))
    clear_jobs(conn)
    decision_table._CACHE.clear()
    wall, cpu = time.perf_counter(), time.process_time()
    programs = instantiate_gears(conn, FIRST_ID, FIRST_ID + count - 1, mode=RunMode(workers=1))
    conn.commit()
    print(json.dumps({'programs': len(programs), 'cpu': time.process_time() - cpu,
                      'wall': time.perf_counter() - wall}))
"""


def tree_of(revision: str | None, into: Path) -> Path:
    """This checkout (None) or the folders of `revision`, unpacked into `into`."""
    if revision is None:
        return REPO
    archived = subprocess.run(["git", "-C", str(REPO), "archive", revision, *FOLDERS], capture_output=True)
    if archived.returncode != 0:
        raise SystemExit(f"error: this checkout has no commit {revision}: {archived.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(into)], input=archived.stdout, check=True)
    return into


def one_run(tree: Path, url: str, count: int) -> dict:
    done = subprocess.run([sys.executable, "-c", DRIVER, str(tree), url, str(count)], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"error: the batch of {tree} failed: {done.stderr.strip()[-800:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def report(runs: dict[str, list[dict]], revision: str, count: int) -> None:
    rates = {}
    for name, found in runs.items():
        assert all(run["programs"] == count for run in found), f"{name}: not every gear got a program: {found}"
        per_cpu = median([count / run["cpu"] for run in found])
        per_wall = median([count / run["wall"] for run in found])
        rates[name] = per_cpu
        print(f"{name:22s}: median {per_cpu:6.0f} programs per CPU second, {per_wall:6.0f} per wall second "
              f"({len(found)} runs of {count} gears)")
    ratio = rates["this tree"] / rates[revision]
    print(f"ratio this tree/{revision} per CPU second = {ratio:.2f} (target >= {TARGET_RATIO:g}): "
          f"{verdict(ratio >= TARGET_RATIO)}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--against", default=BASELINE, metavar="REV", help=f"the earlier commit (default {BASELINE})")
    parser.add_argument("--count", type=int, default=10_000, help="gears in the batch (default 10000)")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each tree (default 3)")
    add_database_argument(parser)
    args = parse_arguments(parser, argv, {"count": 100, "reps": 1})
    with tempfile.TemporaryDirectory(prefix="bench_against_") as folder:
        trees = {"this tree": tree_of(None, Path(folder)), args.against: tree_of(args.against, Path(folder))}
        runs: dict[str, list[dict]] = {name: [] for name in trees}
        for _ in range(args.reps):
            for name, tree in trees.items():
                runs[name].append(one_run(tree, args.database_url, args.count))
    report(runs, args.against, args.count)
    return 0


if __name__ == "__main__":
    sys.exit(main())
