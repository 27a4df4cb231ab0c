"""DXF reading: `ezdxf.readfile` alone against `read_drawing` (load, audit, geometry, chains,
profile, codes) on a generated drawing of about 10,000 entities, alternated run by run in
one process. Target: read_drawing median within 1.5x of the readfile median.

The drawing: on layer 0 a closed half-profile of lines, arcs and bulged LWPOLYLINEs (a
wavy outline from the axis and back), a tool-change POINT; layers 1-3 with tool paths and
@-codes; clutter (lines, circles, text) on a dimension layer.

    python bench/dxf_read.py [--entities 10000] [--runs 7] [--keep FILE.dxf]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import ezdxf  # noqa: E402

from _common import median, verdict  # noqa: E402
from importers.dxf_drawing import read_drawing  # noqa: E402

TARGET_RATIO = 1.5
PITCH = 2.0  # mm along Z per profile wave


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
    for layer, codes in (("1", "@GROUGH @S900 @F0.3 @T01 @M8"), ("2", "@GFINISH @S1200 @F0.1 @T02"),
                         ("3", "@GTHREAD @S600 @T03 @P1.5 @D0.2 @A29")):
        msp.add_text(codes, dxfattribs={"layer": layer, "insert": (5, 40 + int(layer) * 5)})
        for index in range(paths):
            msp.add_line((1, 30 - index * 0.01), (-50, 30 - index * 0.01), dxfattribs={"layer": layer})
    return 3 * (paths + 1)


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
    used += 1 + add_operations(msp, paths=entities // 10 // 3)
    add_clutter(msp, max(0, entities - used))
    doc.saveas(path)


def timed(function, path: Path) -> float:
    start = time.perf_counter()
    function(path)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--entities", type=int, default=10_000)
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--keep", type=Path, help="also write the generated drawing here")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = args.keep or Path(folder) / "bench.dxf"
        make_drawing(path, args.entities)
        drawing = read_drawing(path)
        count = len(ezdxf.readfile(path).modelspace())
        print(f"drawing: {count} entities, profile {len(drawing.profile.segments)} segments "
              f"(closed by axis: {drawing.profile.closed_by_axis}), {len(drawing.operations)} operations")
        plain, full = [], []
        for _ in range(args.runs):
            plain.append(timed(ezdxf.readfile, path))
            full.append(timed(read_drawing, path))
    ratio = median(full) / median(plain)
    print(f"ezdxf.readfile median {median(plain) * 1000:.1f} ms, read_drawing median {median(full) * 1000:.1f} ms "
          f"over {args.runs} runs")
    print(f"ratio {ratio:.2f} (target <= {TARGET_RATIO}) {verdict(ratio <= TARGET_RATIO)}")


if __name__ == "__main__":
    main()
