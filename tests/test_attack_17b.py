"""Attacks on issue 17's side views (adversary review adv2): each test states what a user relies
on — a drawing becomes the part it draws, or is refused in one line with nothing stored — and
fails while the engine turns a different part. Every drawing is built here with ezdxf, and the
part's diameters are the ones the test drew, not the engine's reading of them."""
from __future__ import annotations

import json

import ezdxf
import psycopg
import pytest

from lathe_programs import motions, operation_lines

AXIS_Y = 30.0                 # drawing Y of the part's axis (the view is drawn off Y = 0)
# A stepped shaft, upper half (z, radius): Ø16 to Z-12, Ø24 to Z-35, Ø20 to Z-50.
SHAFT = [(0, 8), (-12, 8), (-12, 12), (-35, 12), (-35, 10), (-50, 10)]
BORE_RADIUS = 3.0             # a Ø6 bore along the axis
DRAWN_DIAMETERS = sorted({2 * r for _, r in SHAFT})


def drawing(path, draw) -> None:
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("Mittellinie", linetype="CENTER")
    draw(doc.modelspace())
    doc.saveas(path)


def outline(msp, axis_y: float = AXIS_Y) -> None:
    upper = [(z, axis_y + r) for z, r in SHAFT]
    msp.add_lwpolyline(upper + [(z, axis_y - r) for z, r in reversed(SHAFT)], close=True)


def centre_line(msp, y: float = AXIS_Y) -> None:
    msp.add_line((5, y), (-55, y), dxfattribs={"layer": "Mittellinie"})


def through_bore_in_solid_lines(msp) -> None:
    """A section through a bored shaft drawn without hatching: the bore's walls are solid lines."""
    outline(msp)
    for side in (BORE_RADIUS, -BORE_RADIUS):
        msp.add_line((0, AXIS_Y + side), (-50, AXIS_Y + side))
    centre_line(msp)


def blind_bore_in_solid_lines(msp) -> None:
    """A bore Ø6 × 20 from the face, its walls and bottom drawn solid (a section without hatching)."""
    outline(msp)
    for side in (BORE_RADIUS, -BORE_RADIUS):
        msp.add_line((0, AXIS_Y + side), (-20, AXIS_Y + side))
    msp.add_line((-20, AXIS_Y - BORE_RADIUS), (-20, AXIS_Y + BORE_RADIUS))
    centre_line(msp)


def section_halves_without_hatch(msp) -> None:
    """The usual section of a bored part: the two cut faces as closed outlines either side of the
    bore, a centre line between them, no hatching."""
    for sign in (1, -1):
        cut = [(z, AXIS_Y + sign * r) for z, r in SHAFT]
        msp.add_lwpolyline([(0, AXIS_Y + sign * BORE_RADIUS)] + cut + [(-50, AXIS_Y + sign * BORE_RADIUS)],
                           close=True)
    centre_line(msp)


def centre_line_off_the_symmetry(msp) -> None:
    """A dash-dot line 5 mm above the outline's symmetry (a pitch line, a leader): not the axis."""
    outline(msp)
    centre_line(msp, AXIS_Y + 5)


BORED = ("through_bore_solid", "blind_bore_solid", "section_without_hatch")
HOSTILE_SIDE_VIEWS = {
    "through_bore_solid": through_bore_in_solid_lines,
    "blind_bore_solid": blind_bore_in_solid_lines,
    "section_without_hatch": section_halves_without_hatch,
    "centre_line_off_symmetry": centre_line_off_the_symmetry,
}


def counts(url) -> tuple[int, int]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


def finish_diameters(run, job_id: int) -> list[float]:
    """The diameters the finish (operation 2 of a profile job) runs along Z at, read from the text."""
    made = run("instantiate", "--job", job_id, "--dry-run")
    assert made.exit_code == 0, made.output
    finish = operation_lines(made.stdout.splitlines(), 2)
    return sorted({round(2 * start[1], 3) for g, start, end in motions(finish)
                   if g == 1 and start[1] == end[1] and start[0] != end[0]})


@pytest.mark.parametrize("name", HOSTILE_SIDE_VIEWS)
def test_a_side_view_is_turned_as_drawn_or_refused(run, tmp_path, name):
    """A bore drawn with solid lines (a section without hatching) cannot be turned from outside,
    and a dash-dot line off the outline's symmetry is not its axis: the engine refuses such a
    drawing in one line, or its job finishes exactly the diameters drawn. A job that turns a solid
    shaft where the drawing has a bore, or every diameter 10 mm under size, is a wrong part."""
    path = tmp_path / f"{name}.dxf"
    drawing(path, HOSTILE_SIDE_VIEWS[name])
    before = counts(run.url)
    made = run("import-dxf", path, "--rough-depth", "1", "--program-name", "ATTACK", "--machine", "lathe-840d",
               "--json")
    if made.exit_code == 1:
        assert made.stderr.count("\n") == 1 and counts(run.url) == before, made.output
        return
    assert made.exit_code == 0, made.output
    report = json.loads(made.stdout)
    assert name not in BORED, f"a part with a Ø{2 * BORE_RADIUS:g} bore became job {report['job_id']}: {report['notes']}"
    assert finish_diameters(run, json.loads(made.stdout)["job_id"]) == DRAWN_DIAMETERS


def ring_section_off_the_axis(msp) -> None:
    """A ring Ø70/Ø50 × 20 as its section in the seed-000 convention (radius = drawing Y): the closed
    rectangle between the bore and the outside, not touching the axis."""
    msp.add_lwpolyline([(0, 25), (-20, 25), (-20, 35), (0, 35)], close=True)


def test_a_ring_drawn_as_its_section_is_not_turned_as_a_solid_bar(run, tmp_path):
    """A closed profile that stays 25 mm off the axis is a ring: its bore Ø50 cannot be turned from
    outside. The job turns the outside Ø70 only and says nothing of the bore — a solid disc where
    the drawing has a ring."""
    path = tmp_path / "ring.dxf"
    drawing(path, ring_section_off_the_axis)
    before = counts(run.url)
    made = run("import-dxf", path, "--rough-depth", "1", "--program-name", "RING", "--machine", "lathe-840d",
               "--json")
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and counts(run.url) == before
