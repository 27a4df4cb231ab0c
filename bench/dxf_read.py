"""DXF import: `ezdxf.readfile` alone against (a) `read_drawing` (load, audit, geometry,
chains, profile, codes) and (b) the whole `engine import-dxf` library call `import_dxf`
(reading, job parameters, the program computed and checked against the lathe, the job
stored in PostgreSQL), on a generated drawing of about 10,000 entities, alternated run by
run in one process. Target: the import's median within 1.5x of the readfile median.

The drawing: on layer 0 a closed half-profile of lines, arcs and bulged LWPOLYLINEs (a
wavy outline from the axis and back), a tool-change POINT; layer 1 ROUGH with one drawn
line per pass, layer 2 FINISH with a drawn path, layer 3 THREAD with crest and root lines,
each with its @-codes; clutter (lines, circles, text) on a dimension layer.

    python bench/dxf_read.py [--entities 10000] [--runs 7] [--keep FILE.dxf] [--database-url URL]
"""
from __future__ import annotations

import argparse
import gc
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import ezdxf  # noqa: E402
from _common import add_database_argument, bench_database, median, parse_arguments, verdict  # noqa: E402

from engine.drawings.drawing import read_drawing  # noqa: E402

TARGET_RATIO = 1.5
PITCH = 0.2  # mm along Z per profile wave: 2,000 waves stay within the lathe's Z travel


def add_profile(msp, waves: int) -> int:
    """Half-profile from the axis at Z=0 to the axis at Z=-waves*PITCH: per wave a line, an
    arc and a bulged LWPOLYLINE (three entities); returns the entity count."""
    radius = 20.0
    msp.add_line((0, 0), (0, radius))
    z = 0.0
    for _ in range(waves):
        msp.add_line((z, radius), (z - PITCH / 4, radius))
        centre = (z - PITCH / 2, radius)
        msp.add_arc(centre, PITCH / 4, 0, 180, is_counter_clockwise=True)  # from z-PITCH/4 to z-3PITCH/4
        msp.add_lwpolyline([(z - 3 * PITCH / 4, radius, -0.4), (z - PITCH, radius, 0)], format="xyb")
        z -= PITCH
    msp.add_line((z, radius), (z, 0))
    return 2 + 3 * waves


def add_operations(msp, paths: int) -> int:
    """ROUGH: one drawn line per pass above the profile; FINISH: a drawn path in 2 lines;
    THREAD: crest and root lines (depth 0.92 mm)."""
    for layer, codes in (("1", "@GROUGH @S900 @F300 @T01 @M8"), ("2", "@GFINISH @S1200 @F100 @T02"),
                         ("3", "@GTHREAD @S600 @T03 @P1.5 @D0.2 @A29")):
        msp.add_text(codes, dxfattribs={"layer": layer, "insert": (5, 40 + int(layer) * 5)})
    for index in range(paths):
        # 0.025 mm apart: more than the 0.01 mm within which ends chain, above the R20.5 profile
        msp.add_line((1, 30 - index * 0.025), (-50, 30 - index * 0.025), dxfattribs={"layer": "1"})
    msp.add_line((0, 21), (-20, 21), dxfattribs={"layer": "2"})
    msp.add_line((-20, 21), (-20, 25), dxfattribs={"layer": "2"})
    for radius in (21.0, 20.08):
        msp.add_line((-1, radius), (-15, radius), dxfattribs={"layer": "3"})
    return paths + 7


def add_clutter(msp, count: int) -> None:
    for index in range(count):
        kind = index % 3
        if kind == 0:
            msp.add_line((index, 100), (index + 1, 110), dxfattribs={"layer": "DIM"})
        elif kind == 1:
            msp.add_circle((index, 120), 2, dxfattribs={"layer": "DIM"})
        else:
            msp.add_text(f"{index}", dxfattribs={"layer": "DIM", "insert": (index, 130)})


def make_drawing(path: Path, entities: int) -> None:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    for name in ("1", "2", "3", "DIM"):
        doc.layers.add(name)
    used = add_profile(msp, waves=entities * 6 // 10 // 3)
    msp.add_point((10, 60))
    used += 1 + add_operations(msp, paths=entities // 30)
    add_clutter(msp, max(0, entities - used))
    doc.saveas(path)


def timed(function, path: Path) -> float:
    """Seconds of the call and of collecting its garbage: the import pauses the cycle
    collector, which must not shift its cost onto the next run (the baseline's)."""
    gc.collect()
    start = time.perf_counter()
    function(path)
    gc.collect()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_database_argument(parser)
    parser.add_argument("--entities", type=int, default=10_000)
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--keep", type=Path, help="also write the generated drawing here")
    args = parse_arguments(parser, None, smoke={"entities": 300, "runs": 1})
    with tempfile.TemporaryDirectory() as folder, bench_database(args.database_url, "bench_dxf") as url:
        path = args.keep or Path(folder) / "bench.dxf"
        make_drawing(path, args.entities)
        drawing = read_drawing(path)
        count = len(ezdxf.readfile(path).modelspace())
        print(f"drawing: {count} entities, profile {len(drawing.profile.segments)} segments "
              f"(closed by axis: {drawing.profile.closed_by_axis}), {len(drawing.operations)} operations")
        plain, read, imported = measure(path, url, args.runs)
    print(f"medians over {args.runs} alternated runs: ezdxf.readfile {median(plain) * 1000:.1f} ms, "
          f"read_drawing {median(read) * 1000:.1f} ms, import_dxf {median(imported) * 1000:.1f} ms")
    for what, times in (("read_drawing", read), ("import_dxf (the target)", imported)):
        ratio = median(times) / median(plain)
        print(f"{what} / ezdxf.readfile: {ratio:.2f} (target <= {TARGET_RATIO}) {verdict(ratio <= TARGET_RATIO)}")


def measure(path: Path, url: str, runs: int) -> tuple[list, list, list]:
    """Alternated runs of the three; each import stores one job (committed)."""
    import psycopg

    from importers.dxf import import_dxf

    plain, read, imported = [], [], []
    with psycopg.connect(url) as conn:
        print(f"import_dxf: job {import_dxf(conn, path).job_id}, untimed first run")
        for _ in range(runs):
            plain.append(timed(ezdxf.readfile, path))
            read.append(timed(read_drawing, path))
            imported.append(timed(lambda p: import_dxf(conn, p), path))
    return plain, read, imported


if __name__ == "__main__":
    main()
