"""`engine import-nc` of long programs: `engine.library.nc_import.import_nc` (the library call
behind the command: read, tokenise, modules, parameter references, the rows checked and stored,
the stored class instantiated and compared with the file) on generated programs of N, 3·N and
10·N lines (default 10,000, 30,000, 100,000), runs alternated. The smallest program is the
baseline measured in the same run: linear growth means the same time per line at every size, a
per-line ratio of 1. Also printed: the absolute time of the largest against the 10 s of issues 13
and 27.

`--program lathe` (the default, issue 27) is what a shop's CAM system or programmer writes for a
Fanuc/Haas-style lathe: a program number with its name, `G50 S` spindle clamps, `G96` surface
speeds, tool calls `T0101`, the roughing cycle `G71 U.. R..`/`G71 P.. Q.. U.. W.. F..` with its
numbered contour and the finishing `G70`, coordinates to three decimals with trailing points,
comments; the feeds, speed and depth of cut are parameters (the clamp and the allowances equal
to them are left alone). `--program hob` is an 840D hobbing program as a CAM system writes it
(issue 13): every block numbered, plunges, axial passes and Y shifts, R parameters and the
electronic gearbox; about one number in five becomes a reference.
Each import is committed (the version snapshot and audit are written at COMMIT) into a copy of the
seeded database made for it, so every run stores the same rows into the same library.

    python bench/import_nc.py [--program lathe|hob] [--lines 10000] [--reps 3] [--keep FILE]
                              [--profile] [--database-url URL]
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

TARGET_SECONDS = 10.0      # issues 13 and 27: 100,000 lines in at most 10 s
LINEAR = 1.1               # time per line of the largest within 1.1x that of the smallest counts as linear
SCALES = (1, 3, 10)        # the sizes, in multiples of --lines
HOB_PARAMS = {"feed_rough": 1.6, "feed_finish": 0.8, "hob_speed": 800, "table_speed": 42.105, "depth": 4.5,
              "shift": 2.5, "clear_z": 60, "approach_x": 85}
LATHE_PARAMS = {"feed_rough": 0.25, "feed_finish": 0.08, "surface_speed": 200,
                "depth_of_cut": {"value": 1.5, "addresses": ["U"]},
                "feed_plunge": {"value": 0.12, "addresses": ["F"]}}


def lathe_program(lines: int, seed: int = 27) -> list[str]:
    """A Fanuc/Haas-style lathe program of `lines` lines: roughing and finishing operations of
    shafts, one after another, each with its tool, clamp, speed and G71/G70 cycle."""
    rng = random.Random(seed)
    out = ["%", "O1027 (SHAFTS LONG)", "(T0101 80 DEG ROUGH R0.8, T0303 35 DEG FINISH R0.4)",
           "G21 G18 G40 G80 G99", "G28 U0. W0."]
    label = 0
    while len(out) < lines - 3:
        label += 2
        start, end = 10 * label, 10 * label + 10
        stock = round(rng.uniform(40, 80), 1)
        out += ["", f"(OPERATION {label // 2}: ROUGH AND FINISH)", "T0101", "G50 S2500", "G96 S200 M03",
                f"G00 X{stock + 2:.1f} Z2.", "M08", "G71 U1.5 R0.5", f"G71 P{start} Q{end} U0.4 W0.1 F0.25",
                f"N{start} G00 G42 X{round(stock / 3, 3)}"]
        x, z = stock / 3, 0.0
        for _ in range(rng.randint(6, 14)):
            x, z = round(x + rng.uniform(0.5, 4), 3), round(z - rng.uniform(2, 15), 3)
            out.append(rng.choice([f"G01 Z{z}", f"G01 X{x} Z{z} F0.12", f"G02 X{x} Z{z} R{round(rng.uniform(2, 9), 3)}",
                                   f"X{x}"]))
        out += [f"N{end} G01 G40 X{stock + 2:.1f}", "G00 X100. Z100. M09", "T0303", "G50 S3000",
                "G96 S200 M03", f"G00 X{stock + 2:.1f} Z2.", f"G70 P{start} Q{end} F0.08", "G00 X100. Z100.",
                "M05", "M01"]
    out = out[:lines - 2]
    return out + ["M30", "%"]


def hob_program(lines: int, seed: int = 13) -> list[str]:
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


PROGRAMS = {"lathe": (lathe_program, LATHE_PARAMS, "NC"), "hob": (hob_program, HOB_PARAMS, "MPF")}


def timed_import(server_url: str, seeded: str, path: Path, gear_class: str, params: dict,
                 profile: bool = False) -> float:
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
            profiler = _profiler() if profile else None
            start = time.perf_counter()
            report = import_nc(conn, path, gear_class, params)
            seconds = time.perf_counter() - start
            if profiler is not None:
                _report_profile(profiler)
            CPU.append((cpu_seconds() - before, backend_cpu_seconds(server) - server_before))
    finally:
        with psycopg.connect(server_url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(copy)))
    if report.rows != len(path.read_text().splitlines()) or not report.created:
        raise SystemExit(f"bench/import_nc.py: {report.rows} rows from {path}")
    return seconds


PROOF_PROFILES: list = []   # the profile of the proof's thread (check, compile, run), which cProfile
                           # of the importing thread does not see


def _profiler():
    import cProfile

    from engine.library.nc_verify import Proof

    if not PROOF_PROFILES:
        unprofiled = Proof.run

        def run(proof) -> None:
            PROOF_PROFILES.append(cProfile.Profile())
            PROOF_PROFILES[-1].runcall(unprofiled, proof)
        Proof.run = run   # type: ignore[method-assign, assignment]   # this process, for the profiled import (the last)
        PROOF_PROFILES.append(cProfile.Profile())
    profiler = cProfile.Profile()
    profiler.enable()
    return profiler


def _report_profile(profiler) -> None:
    """The cProfile top lines of one import, by cumulative and by own time: the importing thread
    (the fork reading the second half of a long program is not profiled), then the proof's thread."""
    import pstats

    profiler.disable()
    for title, stats in (("importing thread", profiler), ("proof thread", PROOF_PROFILES[-1])):
        for order in ("cumulative", "tottime"):
            print(f"--- {title}, by {order} time")
            pstats.Stats(stats).sort_stats(order).print_stats(18)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--program", choices=sorted(PROGRAMS), default="lathe",
                        help="lathe: Fanuc/Haas-style lathe programs (default); hob: 840D hobbing programs")
    parser.add_argument("--lines", type=int, default=10_000, help="lines of the smallest program; then 3x and 10x")
    parser.add_argument("--reps", type=int, default=3, help="alternated runs of each (default 3)")
    parser.add_argument("--keep", type=Path, help="also write the largest program here")
    parser.add_argument("--profile", action="store_true", help="then profile one import of the smallest program")
    args = parse_arguments(parser, argv, smoke={"lines": 200, "reps": 1})
    from psycopg.conninfo import conninfo_to_dict

    make, params, extension = PROGRAMS[args.program]
    sizes = {scale: scale * args.lines for scale in SCALES}
    with bench_database(args.database_url, "bench_import_nc") as url, tempfile.TemporaryDirectory() as folder:
        seeded = conninfo_to_dict(url)["dbname"]
        paths = {scale: Path(folder) / f"long_{scale}.{extension}" for scale in sizes}
        for scale, count in sizes.items():
            paths[scale].write_text("\n".join(make(count)) + "\n")
        if args.keep:
            args.keep.write_bytes(paths[SCALES[-1]].read_bytes())
        times: dict = {scale: [] for scale in sizes}
        cpu: dict = {scale: [] for scale in sizes}
        timed_import(args.database_url, seeded, paths[SCALES[0]], "nc_warm_up", params)   # imports, caches: not timed
        for repetition in range(args.reps):
            for scale in (SCALES if repetition % 2 == 0 else reversed(SCALES)):
                times[scale].append(timed_import(args.database_url, seeded, paths[scale], f"nc_{scale}", params))
                cpu[scale].append(CPU[-1])
        _report(args, sizes, times, cpu)
        if args.profile:   # the smallest: under cProfile the largest's compile passes the check's 7 s of CPU
            timed_import(args.database_url, seeded, paths[SCALES[0]], "nc_profiled", params, profile=True)
    return 0


def _report(args, sizes: dict, times: dict, cpu: dict) -> None:
    largest, smallest = SCALES[-1], SCALES[0]
    per_line = {scale: median(times[scale]) / sizes[scale] for scale in sizes}
    client, server = (median(values) for values in zip(*cpu[largest]))
    print(f"import-nc: {args.program} programs of {', '.join(str(count) for count in sizes.values())} lines, "
          f"{args.reps} alternated runs")
    for scale in sizes:
        own, backend = (median(values) for values in zip(*cpu[scale]))
        print(f"  {sizes[scale]:7d} lines: median {median(times[scale]):6.2f} s wall ({per_line[scale] * 1e6:5.1f} us "
              f"per line, {per_line[scale] / per_line[smallest]:.2f}x that of {sizes[smallest]}), CPU {own:6.2f} s "
              f"here + {backend:6.2f} s server = {own + backend:6.2f} s; runs "
              + ", ".join(f"{t:.2f}" for t in times[scale]))
    print(f"the largest import (medians): {client:.2f} s of CPU in this process and its fork, "
          f"{server:.2f} s in the database server (its backend process: /proc, so only for a server on this "
          f"machine, else nan); load average now {', '.join(f'{load:.2f}' for load in os.getloadavg())} "
          f"on {os.cpu_count()} cores")
    ratio = per_line[largest] / per_line[smallest]
    print(f"per-line time at {sizes[largest]} against {sizes[smallest]} lines: {ratio:.2f} "
          f"(linear <= {LINEAR}): {verdict(ratio <= LINEAR)}")
    print(f"{sizes[largest]} lines in {median(times[largest]):.2f} s (target <= {TARGET_SECONDS} s for 100,000): "
          f"{verdict(sizes[largest] < 100_000 or median(times[largest]) <= TARGET_SECONDS)}")


if __name__ == "__main__":
    sys.exit(main())
