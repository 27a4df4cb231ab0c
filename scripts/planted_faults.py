"""Does the fast subset catch what the suite catches? (issue 28: "a test-fast selection under 60 s,
with the same faults caught"). Each fault below is a one-line break of the engine in a place the
shop relies on; for each, this copies the checkout's tracked files into a temporary folder, plants
the fault there (the checkout itself is never touched) and runs a selection of the suite against
it: `fast` (`pytest -m "not slow"`, as `make test-fast`) by default, `full` for every test. A
fault is caught when at least one test fails. The faults are data: add one where a new kind of
mistake would cost the shop.

    python scripts/planted_faults.py [--selection fast|full] [--only NAME] [--workers 2]

The test server is ENGINE_TEST_DSN (as for pytest), else the embedded server. Exit 1 when a fault
is not caught.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Fault:
    name: str
    path: str          # relative to the checkout
    old: str           # must occur exactly once
    new: str
    harm: str          # what it would do at the machine


FAULTS = (
    Fault("hob-radius", "engine/simulation/hobbing/envelope.py",
          "r, half = hob.radius, hob.half_length", "r, half = hob.radius - 1.0, hob.half_length",
          "the simulation sees a hob 1 mm thinner than it is: collisions of the tip pass"),
    Fault("coupling-sign", "engine/hobbing/conventions.py",
          "return -hand_sign(hob_hand) * starts", "return hand_sign(hob_hand) * starts",
          "EGON turns the table the wrong way: the teeth are cut with the wrong hand"),
    Fault("upper-travel", "engine/verifier/limits.py",
          "if not low <= value <= high:", "if not low <= value:",
          "a move beyond the axis' upper travel is accepted: an overtravel alarm or a crash"),
    Fault("impact-unproved", "engine/release/impact.py",
          "            self.inputs.prove(key, new_lines, job_id)\n", "            pass\n",
          "a release's changed programs are not proved: a draft that breaks stored jobs is released"),
    Fault("import-rounding", "engine/templates/nc_number.py",
          "places = max(decimals, -int(exact.normalize().as_tuple().exponent), 0)", "places = decimals",
          "a new feed is rounded to the file's decimals: F0.025 written F0.03 (+20 %)"),
    Fault("turning-rapid", "engine/simulation/turning/material.py",
          "if through > 0:", "if through > 1e9:",
          "a lathe rapid through the blank or the part is accepted: a broken tool"),
)

SELECTIONS = {"fast": ["-m", "not slow"], "full": []}


def tracked_copy(into: Path) -> None:
    """The checkout's tracked files as they are on disk (uncommitted edits included)."""
    names = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True, check=True).stdout
    for name in filter(None, names.decode().split("\0")):
        source, target = ROOT / name, into / name
        if source.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(source.read_bytes())


def plant(tree: Path, fault: Fault) -> None:
    path = tree / fault.path
    text = path.read_text()
    if text.count(fault.old) != 1:
        raise SystemExit(f"fault {fault.name}: {fault.old!r} is not in {fault.path} exactly once; update the table")
    path.write_text(text.replace(fault.old, fault.new))


def failing_tests(tree: Path, selection: str, workers: int) -> tuple[list[str], float]:
    """The tests that fail on `tree`, and the seconds the run took."""
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rf", *SELECTIONS[selection]]
    command += ["-n", str(workers), "--dist", "worksteal"] if workers > 1 else []
    environment = {**os.environ, "PYTHONPATH": str(tree)}
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    start = time.perf_counter()
    done = subprocess.run(command, cwd=tree, env=environment, capture_output=True, text=True)
    failed = [line.split(" ", 2)[1] for line in done.stdout.splitlines() if line.startswith("FAILED ")]
    if done.returncode not in (0, 1) or (done.returncode == 1 and not failed):
        raise SystemExit(f"pytest did not run ({done.returncode}): {(done.stdout + done.stderr)[-1500:]}")
    return failed, time.perf_counter() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--selection", choices=sorted(SELECTIONS), default="fast")
    parser.add_argument("--only", action="append", choices=[fault.name for fault in FAULTS], help="this fault only")
    parser.add_argument("--workers", type=int, default=2, help="pytest-xdist workers (default 2)")
    args = parser.parse_args(argv)
    missed = []
    for fault in (fault for fault in FAULTS if not args.only or fault.name in args.only):
        with tempfile.TemporaryDirectory(prefix="planted_") as folder:
            tree = Path(folder)
            tracked_copy(tree)
            plant(tree, fault)
            failed, seconds = failing_tests(tree, args.selection, args.workers)
        print(f"{fault.name:16s} {'caught' if failed else 'MISSED'} by {len(failed)} {args.selection} tests "
              f"in {seconds:.0f} s ({fault.harm}){': ' + ', '.join(failed[:3]) if failed else ''}", flush=True)
        if not failed:
            missed.append(fault.name)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
