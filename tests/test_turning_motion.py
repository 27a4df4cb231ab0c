"""Rapid moves of generated lathe programs (design notes §8) never drive the tool into the part
or through the blank: every G0 that changes Z runs at or above the largest radius of the part
and the blank over the Z it travels (or wholly outside the blank's Z span), and no G0 enters
the part region. Printed arcs are well conditioned.

The part region comes from the drawing through ezdxf (profile closed by the axis), the blank
from the job's stored numbers, the moves from the printed program — nothing from the engine's
tool-path code."""
from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from helpers.drawings import DXF, EMCO, seed_drawing
from helpers.lathe_programs import drawn_polylines, motions, words

from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions
from importers.dxf import import_dxf

MACHINES = ("lathe-iso", "lathe-840d")
SAMPLE_MM = 0.05
# The program prints positions to 0.001 mm.
PRINT_TOLERANCE_MM = 0.002
# A printed arc's centre, rebuilt from its printed end points and radius, lies this close.
ARC_CENTRE_TOLERANCE_MM = 0.01
THREAD_G = (32, 33)


COLLAR_OUTSIDE = [(0, 10), (-19, 10), (-19, 8), (-21, 8), (-21, 10), (-30, 10), (-30, 20), (-40, 20),
                  (-40, 10), (-49, 10), (-49, 8), (-51, 8), (-51, 10), (-60, 10)]


def collar_drawing(path: Path) -> None:
    """Shaft ⌀20 with a ⌀40 collar at Z −30…−40 and ⌀16 grooves at Z −19…−21 and −49…−51,
    slotted by one plunge each (the grooves are part of the profile, as the convention has it).
    The shaft is roughed to ⌀21 on both sides of the collar, behind it from the free end at Z −61
    towards the collar: the blank is at least the collar's ⌀40, and a plunge at Z −50 into an
    unroughed blank would rapid through it."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    for layer in ("1", "2", "3"):
        doc.layers.add(layer)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), *COLLAR_OUTSIDE, (-60, 0)])
    msp.add_point((20, 30))
    msp.add_text("@GROUGH @S500 @F200 @T01", dxfattribs={"layer": "1"})
    msp.add_line((1, 10.5), (-29.5, 10.5), dxfattribs={"layer": "1"})
    msp.add_line((-61, 10.5), (-40.5, 10.5), dxfattribs={"layer": "1"})
    msp.add_text("@GSLOT @S300 @F20 @T02", dxfattribs={"layer": "2"})
    msp.add_line((-20, 10), (-20, 8), dxfattribs={"layer": "2"})
    msp.add_line((-50, 10), (-50, 8), dxfattribs={"layer": "2"})
    msp.add_text("@GFINISH @S800 @F100 @T03", dxfattribs={"layer": "3"})
    msp.add_lwpolyline(COLLAR_OUTSIDE, dxfattribs={"layer": "3"})
    doc.saveas(path)


def part_top(polylines, z: float) -> float:
    """The drawn profile's largest radius at z (the region under it reaches the axis), −1 off it."""
    top = -1.0
    for line in polylines:
        for (z0, r0), (z1, r1) in zip(line, line[1:]):
            if min(z0, z1) <= z <= max(z0, z1):
                top = max(top, r0, r1) if z0 == z1 else max(top, r0 + (z - z0) * (r1 - r0) / (z1 - z0))
    return top


def top_over(polylines, low: float, high: float) -> float:
    samples = np.append(np.arange(low, high, SAMPLE_MM), high)
    return max(part_top(polylines, z) for z in samples)


def sampled(start, end):
    count = max(1, math.ceil(math.dist(start, end) / SAMPLE_MM))
    return [(start[0] + (end[0] - start[0]) * n / count, start[1] + (end[1] - start[1]) * n / count)
            for n in range(count + 1)]


def rapid_faults(lines: list[str], polylines, blank) -> list[str]:
    z_front, z_back, blank_radius = blank
    faults, cut = [], None
    for g, start, end in motions(lines):
        if g != 0:
            cut = (g, start, end)
            continue
        if not leaves_its_groove(cut, start, end):
            for z, r in sampled(start, end)[1:-1]:
                if r < part_top(polylines, z) - PRINT_TOLERANCE_MM:
                    faults.append(f"G0 {start}→{end} enters the part at Z{z:.3f} R{r:.3f}")
                    break
        cut = None
        low, high = sorted((start[0], end[0]))
        if high - low <= PRINT_TOLERANCE_MM or high < z_back or low > z_front:
            continue
        needed = max(top_over(polylines, low, high), blank_radius)
        if min(start[1], end[1]) < needed - PRINT_TOLERANCE_MM:
            faults.append(f"G0 {start}→{end} travels in Z below R{needed:.3f} (part and blank)")
    return faults


def leaves_its_groove(cut, start, end) -> bool:
    """An outward X-only rapid right after a thread pass or a plunge at that Z leaves the
    groove that cut has just made below the drawn profile."""
    if cut is None or start[0] != end[0] or end[1] <= start[1]:
        return False
    g, cut_start, cut_end = cut
    return g in THREAD_G or (g == 1 and cut_start[0] == cut_end[0] == start[0])


def blank_of(conn, job_id: int, polylines):
    params = conn.execute("SELECT params FROM job WHERE id = %s", (job_id,)).fetchone()[0]
    if params.get("stock_diameter") is None:   # no blank stored: the part is all there is
        zs = [z for line in polylines for z, _ in line]
        return max(zs), min(zs), 0.0
    return params["stock_z_front"], params["stock_z_back"], params["stock_diameter"] / 2.0


def program_and_blank(conn, path: Path, machine: str, options: ProfileOptions):
    report = import_dxf(conn, path, machine, options, None, "DRAWN_PART")   # the Emco file names are too long
    polylines = drawn_polylines(path)
    return instantiate_job(conn, report.job_id).lines, polylines, blank_of(conn, report.job_id, polylines)


def drawings(tmp_path: Path):
    seed_drawing(tmp_path / "part.dxf")
    collar_drawing(tmp_path / "collar.dxf")
    yield tmp_path / "part.dxf", ProfileOptions()
    yield tmp_path / "collar.dxf", ProfileOptions()
    for name in EMCO:
        yield DXF / name, ProfileOptions(rough_depth=1.0)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@pytest.mark.parametrize("machine", MACHINES)
def test_no_rapid_enters_the_part_or_the_blank(conn, tmp_path, machine):
    for path, options in drawings(tmp_path):
        lines, polylines, blank = program_and_blank(conn, path, machine, options)
        assert rapid_faults(lines, polylines, blank) == [], path.name


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("machine", MACHINES)
def test_tool_change_blocks_move_z_only(conn, tmp_path, machine):
    """Leaving the work X goes up first; the tool-change block then moves Z alone."""
    seed_drawing(tmp_path / "part.dxf")
    lines, _, _ = program_and_blank(conn, tmp_path / "part.dxf", machine, ProfileOptions())
    changes = [g for g in motions(lines) if g[0] == 0 and g[2] == pytest.approx(tool_change_of(lines))]
    assert changes
    for _, start, end in changes:
        assert start[1] == pytest.approx(end[1], abs=PRINT_TOLERANCE_MM), (start, end)


def tool_change_of(lines: list[str]) -> tuple[float, float]:
    last = [words(line) for line in lines if line.startswith(("G00 X", "G0 X"))][-1]
    return last["Z"], last["X"] / 2.0


def arc_centre(start, end, radius: float, ccw: bool):
    """The centre of the short arc (≤ 180°) from start to end with this radius, G3 if ccw."""
    (z0, r0), (z1, r1) = start, end
    chord = math.dist(start, end)
    assert chord <= 2 * radius, (start, end, radius)
    height = math.sqrt(radius * radius - chord * chord / 4)
    uz, ur = (z1 - z0) / chord, (r1 - r0) / chord
    side = 1.0 if ccw else -1.0
    return (z0 + z1) / 2 - side * ur * height, (r0 + r1) / 2 + side * uz * height


@pytest.mark.parametrize("name", EMCO)
@pytest.mark.parametrize("machine", MACHINES)
def test_printed_arcs_rebuild_their_centre(conn, machine, name):
    lines, polylines, _ = program_and_blank(conn, DXF / name, machine, ProfileOptions(rough_depth=1.0))
    arcs = [(line, g, start, end) for line, (g, start, end) in arc_blocks(lines)]
    assert arcs
    for line, g, start, end in arcs:
        radius = float(line.rsplit("R", 1)[1].lstrip("="))
        centre = arc_centre(start, end, radius, g == 3)
        # The true centre: that of the drawn circle, from the drawn arc's own points.
        exact = exact_centre(polylines, start, end)
        assert math.dist(centre, exact) <= ARC_CENTRE_TOLERANCE_MM, line


def arc_blocks(lines: list[str]):
    blocks = [line for line in lines if words(line).get("G") in (0, 1, 2, 3, 32, 33) and ("X" in line or "Z" in line)]
    for line, motion in zip(blocks[1:], motions(blocks)):
        if motion[0] in (2, 3):
            yield line, motion


def exact_centre(polylines, start, end):
    """The centre of the drawn circle through the drawn points nearest this arc's ends and the
    drawn point of the arc farthest from its chord."""
    points = [p for line in polylines for p in line]
    a = min(points, key=lambda p: math.dist(p, start))
    b = min(points, key=lambda p: math.dist(p, end))
    span = math.dist(start, end)
    near = [p for p in points if max(math.dist(p, start), math.dist(p, end)) < span]
    c = max(near, key=lambda p: abs((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])))
    return circumcentre(a, b, c)


def circumcentre(a, b, c):
    ax, ay = a
    bx, by = b
    cx, cy = c
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    ux = ((ax ** 2 + ay ** 2) * (by - cy) + (bx ** 2 + by ** 2) * (cy - ay) + (cx ** 2 + cy ** 2) * (ay - by)) / d
    uy = ((ax ** 2 + ay ** 2) * (cx - bx) + (bx ** 2 + by ** 2) * (ax - cx) + (cx ** 2 + cy ** 2) * (bx - ax)) / d
    return ux, uy
