"""Single-gear latency: `engine instantiate --gear 42 --json` as a subprocess against a bare
`python -c` that connects to the same database and runs one query, same interpreter,
alternated run by run. The CLI runs from a copy of this checkout's engine/ in two modes, both
timed in the same rounds as the baseline: "compiled", its bytecode compiled beforehand (as an
installed wheel has it), and "source", no bytecode (`python -B`: every start compiles the
engine's modules, as a checkout without __pycache__ does). Targets (issue 28): compiled within
1.6x of the baseline median, source within 2.0x. `--against REV` times the CLI of an earlier
commit the same way in the same rounds (before and after, one machine state).

CLI start-up: `engine --help` of this tree against `engine --help` of an earlier commit
(`--help-against REV`, default the commit before the package was laid out in folders), both
run as `python -c` from their own source tree with the same interpreter and packages,
alternated. Target: within noise of the earlier commit (ratio <= 1.10).

    python bench/latency.py [--runs 15] [--against REV] [--help-against REV] [--no-help-startup]
                            [--database-url postgresql://postgres@127.0.0.1:5432/postgres]
"""
from __future__ import annotations

import argparse
import compileall
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import add_database_argument, bench_database, median, parse_arguments, verdict  # noqa: E402

TARGETS = {"compiled": 1.6, "source": 2.0}   # issue 28 (issue 12: 2.0 for the installed CLI)
MODES = tuple(TARGETS)
DATA_FOLDERS = ("migrations", "schema", "seed_templates")
GEAR_ID = 42
HELP_AGAINST = "30ac394"          # main before engine/ was laid out as the design's sections (issue 11)
HELP_TARGET_RATIO = 1.10          # "as fast as before, within noise" on this 2-core machine
REPO = Path(__file__).resolve().parent.parent


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


def cli_code() -> str:
    """`python -c` code running `engine ARGS` from the source tree given as its first argument."""
    return ("import sys; sys.path.insert(0, sys.argv[1]); import engine.cli as cli; "
            "assert cli.__file__.startswith(sys.argv[1]), cli.__file__; "
            "sys.argv = ['engine', *sys.argv[2:]]; cli.main()")


def copy_of_tree(into: Path, revision: str | None) -> Path:
    """This checkout's engine/ (and importers/) as on disk (revision None), or those of `revision`,
    without any bytecode, in `into`."""
    into.mkdir(parents=True)
    if revision is None:
        for package in ("engine", "importers"):
            if (REPO / package).is_dir():
                shutil.copytree(REPO / package, into / package, ignore=shutil.ignore_patterns("__pycache__"))
    elif source_tree_of(revision, into) is None:
        sys.exit(f"bench/latency.py: this checkout has no commit {revision}")
    data_folders(into / "engine_data", revision)
    return into


def data_folders(into: Path, revision: str | None) -> None:
    """migrations/, schema/ and seed_templates/ as a wheel ships them (engine_data/ beside engine/,
    engine.paths), of this checkout or of `revision`."""
    into.mkdir()
    if revision is None:
        for folder in DATA_FOLDERS:
            shutil.copytree(REPO / folder, into / folder)
        return
    archived = subprocess.run(["git", "-C", str(REPO), "archive", revision, *DATA_FOLDERS], capture_output=True,
                              check=True)
    subprocess.run(["tar", "-x", "-C", str(into)], input=archived.stdout, check=True)


def cli_commands(tree: Path, arguments: list[str]) -> dict[str, list[str]]:
    """The CLI from `tree` in both modes: "compiled" from a copy compiled now (every later start
    reads the bytecode), "source" from a copy run with -B (every start compiles; none is written)."""
    compiled = tree.with_name(tree.name + "_compiled")
    shutil.copytree(tree, compiled)
    if not compileall.compile_dir(str(compiled), quiet=1):
        sys.exit(f"bench/latency.py: the engine in {tree} does not compile")
    return {"compiled": [sys.executable, "-c", cli_code(), str(compiled), *arguments],
            "source": [sys.executable, "-B", "-c", cli_code(), str(tree), *arguments]}


def time_rounds(commands: dict, runs: int) -> dict[str, list[float]]:
    """One untimed run of each (the first start reads the files from disk), then `runs` rounds
    of all of them in turn."""
    for what, command in commands.items():
        check(timed(command)[1], what)
    times: dict[str, list[float]] = {what: [] for what in commands}
    for _ in range(runs):
        for what, command in commands.items():
            seconds, completed = timed(command)
            check(completed, what)
            if what != "bare":
                json.loads(completed.stdout)   # the CLI answered with its JSON
            times[what].append(seconds)
    return times


def report(times: dict[str, list[float]], trees: list[str]) -> None:
    bare = median(times["bare"])
    print(f"bare python -c connect + select 1             : median {bare * 1000:7.1f} ms "
          f"(min {min(times['bare']) * 1000:.1f}, max {max(times['bare']) * 1000:.1f})")
    for tree in trees:
        for mode in MODES:
            values = times[f"{tree} {mode}"]
            ratio = median(values) / bare
            print(f"engine instantiate --gear {GEAR_ID}, {tree:<12} {mode:<8}: median {median(values) * 1000:7.1f} ms "
                  f"(min {min(values) * 1000:.1f}), ratio {ratio:.2f}x (target <= {TARGETS[mode]}x): "
                  f"{verdict(ratio <= TARGETS[mode])}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--runs", type=int, default=15, help="alternated rounds of every command (default 15)")
    parser.add_argument("--against", metavar="REV", help="also time the CLI of this commit, in the same rounds")
    parser.add_argument("--help-against", default=HELP_AGAINST, metavar="REV",
                        help=f"commit whose `engine --help` start-up is the baseline (default {HELP_AGAINST})")
    parser.add_argument("--no-help-startup", action="store_true", help="skip the `engine --help` comparison")
    args = parse_arguments(parser, argv, smoke={"runs": 1})

    trees = {"this tree": None, **({args.against: args.against} if args.against else {})}
    with bench_database(args.database_url, "bench_latency") as url, \
            tempfile.TemporaryDirectory(prefix="bench_latency_") as folder:
        arguments = ["--database-url", url, "instantiate", "--gear", str(GEAR_ID), "--json"]
        commands = {"bare": [sys.executable, "-c",
                             f"import psycopg; c=psycopg.connect({url!r}); c.execute('select 1').fetchone()"]}
        for number, (name, revision) in enumerate(trees.items()):
            tree = copy_of_tree(Path(folder) / f"tree{number}", revision)
            commands.update({f"{name} {mode}": command for mode, command in cli_commands(tree, arguments).items()})
        times = time_rounds(commands, args.runs)

    print(f"latency: {args.runs} alternated rounds, interpreter {sys.executable}")
    report(times, list(trees))
    if not args.no_help_startup:
        help_startup(args.help_against, args.runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
