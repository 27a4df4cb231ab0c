"""Single-gear latency: `engine instantiate --gear 42 --json` as a subprocess against a bare
`python -c` that connects to the same database and runs one query, same interpreter,
alternated run by run. Target: CLI median within 2.5x of the baseline median.

    python bench/latency.py [--runs 15] [--database-url postgresql://postgres@127.0.0.1:5432/postgres]
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import add_database_argument, bench_database, median, verdict  # noqa: E402

TARGET_RATIO = 2.5
GEAR_ID = 42


def engine_command() -> str:
    """The console script installed next to this interpreter (the venv's `engine`)."""
    beside = Path(sys.executable).parent / "engine"
    if beside.exists():
        return str(beside)
    found = shutil.which("engine")
    if found is None:
        sys.exit("bench/latency.py: no `engine` console script next to this Python nor on PATH; "
                 "install the project (pip install -e .)")
    return found


def timed(command: list[str]) -> tuple[float, subprocess.CompletedProcess]:
    start = time.perf_counter()
    completed = subprocess.run(command, capture_output=True, text=True)
    return time.perf_counter() - start, completed


def check(completed: subprocess.CompletedProcess, what: str) -> None:
    if completed.returncode != 0:
        raise RuntimeError(f"{what} exited {completed.returncode}: {completed.stderr.strip()[:500]}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--runs", type=int, default=15, help="alternated runs of each command (default 15)")
    args = parser.parse_args(argv)

    with bench_database(args.database_url, "bench_latency") as url:
        cli = [engine_command(), "--database-url", url, "instantiate", "--gear", str(GEAR_ID), "--json"]
        bare = [sys.executable, "-c",
                f"import psycopg; c=psycopg.connect({url!r}); c.execute('select 1').fetchone()"]
        # one untimed run of each: the first start reads the files from disk
        for command, what in ((cli, "engine CLI"), (bare, "bare baseline")):
            check(timed(command)[1], what)
        cli_times, bare_times, lines = [], [], None
        for _ in range(args.runs):
            seconds, completed = timed(cli)
            check(completed, "engine CLI")
            cli_times.append(seconds)
            lines = json.loads(completed.stdout)["lines"]
            seconds, completed = timed(bare)
            check(completed, "bare baseline")
            bare_times.append(seconds)

    cli_median, bare_median = median(cli_times), median(bare_times)
    ratio = cli_median / bare_median
    print(f"latency: {args.runs} alternated runs each, interpreter {sys.executable}")
    print(f"engine instantiate --gear {GEAR_ID} --json : median {cli_median * 1000:7.1f} ms "
          f"(min {min(cli_times) * 1000:.1f}, max {max(cli_times) * 1000:.1f}; {lines} lines)")
    print(f"bare python -c connect + select 1      : median {bare_median * 1000:7.1f} ms "
          f"(min {min(bare_times) * 1000:.1f}, max {max(bare_times) * 1000:.1f})")
    print(f"ratio CLI/baseline = {ratio:.2f}x (target <= {TARGET_RATIO}x): {verdict(ratio <= TARGET_RATIO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
