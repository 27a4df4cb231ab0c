"""`engine import-nc` of a long 840D hobbing program: `engine.library.nc_import.import_nc` (the
library call behind the command: read, tokenise, modules, parameter references, the rows checked
and stored, the stored class instantiated and compared with the file) on generated programs of
N and 10·N lines, runs alternated. The small program is the baseline measured in the same run:
linear growth means a ratio of 10. Also printed: the time per line, and the large import against
the 10 s of issue 13.

The programs are what a CAM system writes for a hob: every block numbered (so no two lines are
alike, as in tests/data/nc/sinumerik/cam_840dsl), plunges, axial passes and shifts of Y with
coordinates to three decimals, comments, R parameters and the electronic gearbox; the job's
feed, speeds, depth and shift are parameters, so about one number in five becomes a reference.
Each import is committed (the version snapshot and audit are written at COMMIT) into a copy of the
seeded database made for it, so every run stores the same rows into the same library.

    python bench/import_nc.py [--lines 10000] [--reps 3] [--keep FILE.MPF] [--database-url URL]
"""
from __future__ import annotations

import argparse
import os
import random
import resource
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from _common import add_database_argument, bench_database, median, parse_arguments, url_of, verdict  # noqa: E402

TARGET_SECONDS = 10.0      # issue 13: 100,000 lines in at most 10 s
LINEAR = 11.0              # 10x the lines in at most 11x the time counts as linear
PARAMS = {"feed_rough": 1.6, "feed_finish": 0.8, "hob_speed": 800, "table_speed": 42.105, "depth": 4.5,
          "shift": 2.5, "clear_z": 60, "approach_x": 85}


def program(lines: int, seed: int = 13) -> list[str]:
    """An 840D hobbing program of `lines` numbered blocks."""
    rng = random.Random(seed)
    out = ["%_N_HOB_LONG_MPF", ";$PATH=/_N_MPF_DIR", "; GEAR 4711 m=3 z=41 beta=15 HOB m=3 z0=1"]
    block = 0

    def add(text: str) -> None:
        nonlocal block
        block += 10
        out.append(f"N{block} {text}")

    add("G90 G71 G94 G17")
    add('T="HOB_M3_AA" D1')
    add("M3 S800 M8")
    add("EGDEF(C,B,1)")
    add('EGON(C,"FINE",B,-1,41)')
    y = 0.0
    while len(out) < lines - 4:
        x = round(rng.uniform(70, 84), 3)
        z_top, z_bottom = round(rng.uniform(2, 8), 3), round(-rng.uniform(20, 60), 3)
        y = round(y + 2.5, 3) if rng.random() < 0.2 else round(rng.uniform(-40, 40), 3)
        for text in (f"; PASS {block // 10} DEPTH {round(85 - x, 3)}", f"G0 X85 Y{y} Z60", f"G0 Z{z_top}",
                     f"G1 X{x} F1.6",
                     f"G1 Z{z_bottom} F{rng.choice(['1.6', '0.8', str(round(rng.uniform(0.5, 2), 2))])}",
                     f"R1={round(rng.uniform(0, 5), 3)}", "G1 X=R1+85", "G0 X85", "G0 Z60"):
            add(text)
    while len(out) < lines - 1:
        add("M9")
    out.append("M30")
    return out[:lines]


CPU: list[tuple[float, float]] = []   # (this process and its forks, the database backend) per import


def cpu_seconds() -> float:
    """CPU time of this process and of its children that have ended (the import's fork)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def backend_cpu_seconds(pid: int) -> float:
    """CPU time of the server process of a connection (the server runs on this machine), else NaN."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def timed_import(server_url: str, seeded: str, path: Path, gear_class: str) -> float:
    """One import, committed, into a copy of the seeded database made for it and dropped after."""
    import uuid

    import psycopg
    from psycopg import sql

    from engine.library.nc_import import import_nc

    copy = f"{seeded}_{uuid.uuid4().hex[:6]}"
    with psycopg.connect(server_url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE DATABASE {} TEMPLATE {}").format(sql.Identifier(copy), sql.Identifier(seeded)))
    try:
        with psycopg.connect(url_of(server_url, copy)) as conn:
            server, before = conn.info.backend_pid, cpu_seconds()
            server_before = backend_cpu_seconds(server)
            start = time.perf_counter()
            report = import_nc(conn, path, gear_class, PARAMS)
            seconds = time.perf_counter() - start
            CPU.append((cpu_seconds() - before, backend_cpu_seconds(server) - server_before))
    finally:
        with psycopg.connect(server_url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(copy)))
    if report.rows != len(path.read_text().splitlines()) or not report.created:
        raise SystemExit(f"bench/import_nc.py: {report.rows} rows from {path}")
    return seconds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--lines", type=int, default=10_000, help="lines of the small program; the large has 10x")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each (default 3)")
    parser.add_argument("--keep", type=Path, help="also write the large program here")
    args = parse_arguments(parser, argv, smoke={"lines": 200, "reps": 1})
    from psycopg.conninfo import conninfo_to_dict

    sizes = {"small": args.lines, "large": 10 * args.lines}
    with bench_database(args.database_url, "bench_import_nc") as url, tempfile.TemporaryDirectory() as folder:
        seeded = conninfo_to_dict(url)["dbname"]
        paths = {name: Path(folder) / f"{name}.MPF" for name in sizes}
        for name, count in sizes.items():
            paths[name].write_text("\n".join(program(count)) + "\n")
        if args.keep:
            args.keep.write_bytes(paths["large"].read_bytes())
        times, cpu = {name: [] for name in sizes}, {name: [] for name in sizes}
        timed_import(args.database_url, seeded, paths["small"], "nc_warm_up")   # imports, caches: not timed
        for repetition in range(args.reps):
            for name in (sizes if repetition % 2 == 0 else reversed(list(sizes))):
                times[name].append(timed_import(args.database_url, seeded, paths[name], f"nc_{name}"))
                cpu[name].append(CPU[-1])
    small, large = median(times["small"]), median(times["large"])
    client, server = (median(values) for values in zip(*cpu["large"]))
    print(f"import-nc: 840D programs of {sizes['small']} and {sizes['large']} numbered lines, "
          f"{args.reps} alternated runs")
    for name in sizes:
        print(f"  {sizes[name]:7d} lines: median {median(times[name]):6.2f} s "
              f"({median(times[name]) / sizes[name] * 1e6:5.1f} us per line); runs "
              + ", ".join(f"{t:.2f}" for t in times[name]))
    print(f"the large import (medians): {client:.2f} s of CPU in this process and its fork, "
          f"{server:.2f} s in the database server; "
          f"load average now {', '.join(f'{load:.2f}' for load in os.getloadavg())} on {os.cpu_count()} cores")
    growth = large / small
    print(f"growth: 10x the lines took {growth:.2f}x the time (linear <= {LINEAR}x): {verdict(growth <= LINEAR)}")
    print(f"{sizes['large']} lines in {large:.2f} s (target <= {TARGET_SECONDS} s for 100,000): "
          f"{verdict(sizes['large'] < 100_000 or large <= TARGET_SECONDS)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
