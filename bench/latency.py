"""Single-gear latency: `engine instantiate --gear 42 --json` as a subprocess against a bare
`python -c` that connects to the same database and runs one query, same interpreter,
alternated run by run. Target: CLI median within 2.0x of the baseline median (issue 12).

CLI start-up: `engine --help` of this tree against `engine --help` of an earlier commit
(`--help-against REV`, default the commit before the package was laid out in folders), both
run as `python -c` from their own source tree with the same interpreter and packages,
alternated. Target: within noise of the earlier commit (ratio <= 1.10).

    python bench/latency.py [--runs 15] [--help-against REV] [--no-help-startup]
                            [--database-url postgresql://postgres@127.0.0.1:5432/postgres]
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import add_database_argument, bench_database, median, parse_arguments, verdict  # noqa: E402

TARGET_RATIO = 2.0          # issue 12 (was 2.5)
GEAR_ID = 42
HELP_AGAINST = "30ac394"          # main before engine/ was laid out as the design's sections (issue 11)
HELP_TARGET_RATIO = 1.10          # "as fast as before, within noise" on this 2-core machine
REPO = Path(__file__).resolve().parent.parent


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


def help_command(tree: Path) -> list[str]:
    """`engine --help` of the source tree `tree`, imported from there ahead of any installed copy."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import engine.cli as cli; "
            "assert cli.__file__.startswith(sys.argv[1]), cli.__file__; cli.main(['--help'])")
    return [sys.executable, "-c", code, str(tree)]


def source_tree_of(revision: str, into: Path) -> Path | None:
    """The engine/ folder of `revision` (and the top-level importers/ folder, which held the DXF reader
    until issue 25 moved it to engine/drawings/), unpacked into `into`; None when this checkout does not have the
    commit (a shallow clone, an unpacked archive)."""
    had_importers = subprocess.run(["git", "-C", str(REPO), "cat-file", "-e", f"{revision}:importers"],
                                   capture_output=True).returncode == 0
    archived = subprocess.run(["git", "-C", str(REPO), "archive", revision, "engine",
                               *(["importers"] if had_importers else [])], capture_output=True)
    if archived.returncode != 0:
        return None
    subprocess.run(["tar", "-x", "-C", str(into)], input=archived.stdout, check=True)
    return into


def help_startup(revision: str, runs: int) -> None:
    """Prints the median start-up of `engine --help` here and at `revision`, alternated, and their ratio."""
    with tempfile.TemporaryDirectory(prefix="bench_help_") as folder:
        earlier = source_tree_of(revision, Path(folder))
        if earlier is None:
            print(f"engine --help start-up: not compared, this checkout has no commit {revision} "
                  "(give --help-against REV)")
            return
        commands = {"this tree": help_command(REPO), revision: help_command(earlier)}
        for what, command in commands.items():   # untimed: the first start reads files and writes bytecode
            check(timed(command)[1], f"engine --help ({what})")
        times = {what: [] for what in commands}
        for _ in range(runs):
            for what, command in commands.items():
                seconds, completed = timed(command)
                check(completed, f"engine --help ({what})")
                times[what].append(seconds)
    now, before = median(times["this tree"]), median(times[revision])
    print(f"engine --help, this tree               : median {now * 1000:7.1f} ms "
          f"(min {min(times['this tree']) * 1000:.1f})")
    print(f"engine --help at {revision:<22}: median {before * 1000:7.1f} ms (min {min(times[revision]) * 1000:.1f})")
    print(f"ratio this tree/{revision} = {now / before:.2f}x (target <= {HELP_TARGET_RATIO}x): "
          f"{verdict(now / before <= HELP_TARGET_RATIO)}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--runs", type=int, default=15, help="alternated runs of each command (default 15)")
    parser.add_argument("--help-against", default=HELP_AGAINST, metavar="REV",
                        help=f"commit whose `engine --help` start-up is the baseline (default {HELP_AGAINST})")
    parser.add_argument("--no-help-startup", action="store_true", help="skip the `engine --help` comparison")
    args = parse_arguments(parser, argv, smoke={"runs": 1})

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
    if not args.no_help_startup:
        help_startup(args.help_against, args.runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
