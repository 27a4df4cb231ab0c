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
from test_instantiate_class import import_emco

from engine.paths import SAMPLE_DRAWING

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
def whole_view_off_y0_without_centre_line(msp) -> None:
    """The whole shaft drawn about drawing Y 30, symmetric, no centre line: at Y 0 the engine halves
    such a view at its symmetry; here it reads a ring Ø36…Ø84 about Y 0 and turns its outside
    (Ø76/Ø84/Ø80) — not the shaft, and not the ring either, whose bore cannot be turned."""
    outline(msp)


HOSTILE_SIDE_VIEWS = {
    "through_bore_solid": through_bore_in_solid_lines,
    "blind_bore_solid": blind_bore_in_solid_lines,
    "section_without_hatch": section_halves_without_hatch,
    "centre_line_off_symmetry": centre_line_off_the_symmetry,
    "whole_view_off_y0_without_centre_line": whole_view_off_y0_without_centre_line,
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
    assert name not in BORED, \
        f"a part with a Ø{2 * BORE_RADIUS:g} bore became job {report['job_id']}: {report['notes']}"
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


# --- drawn operations and the blank -------------------------------------------------------------------

BLANK_DIAMETER = 44.0          # the sample's blank, as its NOTES layer says: Ø44 × 70, face at Z 0
BLANK_Z = (-70.0, 0.0)
INSIDE_MM = 0.01               # deeper than this inside the blank is through material
SAMPLES_PER_MOVE = 40


def without_layer(source, layer: str, path):
    doc = ezdxf.readfile(source)
    for entity in [e for e in doc.modelspace() if e.dxf.layer == layer]:
        doc.modelspace().delete_entity(entity)
    doc.saveas(path)
    return path


def inside_the_blank(point) -> bool:
    z, radius = point
    return (BLANK_Z[0] + INSIDE_MM < z < BLANK_Z[1] - INSIDE_MM
            and radius < BLANK_DIAMETER / 2 - INSIDE_MM)


def rapids_before_the_first_cut(lines: list[str]):
    """The G0 moves before the program's first feed move: the blank is still whole then."""
    found = []
    for g, start, end in motions(lines):
        if g != 0:
            break
        found.append((start, end))
    return found


def test_no_rapid_runs_into_the_uncut_blank_when_the_rough_layer_is_left_out(run, tmp_path):
    """The sample drawing without its ROUGH layer (a shop that roughs on another machine draws
    only SLOT, FINISH, THREAD) imported with its blank Ø44 given: the first operation's approach
    is a rapid from outside the blank straight down to the slot's start, through 9.5 mm of
    uncut steel. With the blank known the engine must keep rapids out of it or refuse."""
    drawing_path = without_layer(SAMPLE_DRAWING, "1", tmp_path / "no_rough.dxf")
    before = counts(run.url)
    made = run("import-dxf", drawing_path, "--stock-diameter", BLANK_DIAMETER, "--json")
    if made.exit_code == 1:
        assert made.stderr.count("\n") == 1 and counts(run.url) == before, made.output
        return
    assert made.exit_code == 0, made.output
    program = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--dry-run")
    assert program.exit_code == 0, program.output
    through = [(start, end) for start, end in rapids_before_the_first_cut(program.stdout.splitlines())
               if any(inside_the_blank((start[0] + (end[0] - start[0]) * k / SAMPLES_PER_MOVE,
                                        start[1] + (end[1] - start[1]) * k / SAMPLES_PER_MOVE))
                      for k in range(SAMPLES_PER_MOVE + 1))]
    assert through == []


# --- instantiate --class: the parameters file ------------------------------------------------------------

def class_job_dry_run(run, tmp_path, text: str):
    params = tmp_path / "params.json"
    params.write_text(text)
    return run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft", "--params", params,
               "--dry-run")


def test_a_deeply_nested_parameters_file_is_bad_input_not_a_bug(run, tmp_path):
    """A parameters file that is not an object of values (here an array nested 100 000 deep) is
    refused in one line, exit 1, like any other file that is not {"name": value}."""
    import_emco(run, tmp_path)
    made = class_job_dry_run(run, tmp_path, "[" * 100_000 + "]" * 100_000)
    assert made.exit_code == 1, made.output
    assert made.stderr.startswith("error: ") and made.stderr.count("\n") == 1


def test_addresses_the_class_does_not_bind_are_not_silently_ignored(run, tmp_path):
    """The class binds feed to F (import-nc --params). A file saying feed binds S asks for a
    different program than the one made: the engine makes F100 and keeps S600 without a word.
    It must refuse, naming the address the class binds."""
    import_emco(run, tmp_path)
    made = class_job_dry_run(run, tmp_path, json.dumps({"feed": {"value": 100, "addresses": ["S"]}}))
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and "F" in made.stderr


LOWER_HALVES = {   # the lower half as drawn, (z, radius) below the centre line; the upper half is SHAFT
    "collar_shorter_below": [(0, 8), (-12, 8), (-12, 12), (-30, 12), (-30, 10), (-50, 10)],
    "every_radius_smaller_below": [(z, 0.9 * r) for z, r in SHAFT],
}


@pytest.mark.parametrize("name", LOWER_HALVES)
def test_a_side_view_whose_halves_disagree_is_refused(run, tmp_path, name):
    """A turned part is the same above and below its axis. When the drawn halves disagree (the
    collar ends at Z-35 above and Z-30 below; Ø24 above and Ø21.6 below) the drawing does not say
    which part to make; the engine silently takes the upper half."""
    lower = LOWER_HALVES[name]

    def draw(msp):
        msp.add_lwpolyline([(z, AXIS_Y + r) for z, r in SHAFT] + [(z, AXIS_Y - r) for z, r in reversed(lower)],
                           close=True)
        centre_line(msp)
    path = tmp_path / f"{name}.dxf"
    drawing(path, draw)
    before = counts(run.url)
    made = run("import-dxf", path, "--rough-depth", "1", "--program-name", "HALVES", "--machine", "lathe-840d")
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and counts(run.url) == before


def test_a_drawing_whose_header_says_imperial_is_not_turned_in_millimetres(run, tmp_path):
    """$INSUNITS unset but $MEASUREMENT 0 (English): the drawing's numbers are inches. The shaft
    drawn 0.945 in (Ø24 mm) across becomes a Ø0.945 mm job, with only a note that lengths were
    taken as millimetres. Scale it, or refuse and ask for the units."""
    inch = 25.4

    def draw(msp):
        msp.add_lwpolyline([(z / inch, r / inch) for z, r in SHAFT] + [(z / inch, -r / inch)
                                                                       for z, r in reversed(SHAFT)],
                           close=True)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 0
    doc.header["$MEASUREMENT"] = 0
    draw(doc.modelspace())
    path = tmp_path / "imperial.dxf"
    doc.saveas(path)
    before = counts(run.url)
    made = run("import-dxf", path, "--rough-depth", "0.1", "--program-name", "IMPERIAL", "--machine", "lathe-840d",
               "--json")
    if made.exit_code == 1:
        assert made.stderr.count("\n") == 1 and counts(run.url) == before, made.output
        return
    assert made.exit_code == 0, made.output
    assert finish_diameters(run, json.loads(made.stdout)["job_id"]) == pytest.approx(DRAWN_DIAMETERS, abs=0.01)


# A half-profile (seed-000 convention, radius = drawing Y) with an undercut: the collar Ø20 from
# the face to Z-10 overhangs a pocket r 4…6 that reaches forward to Z-6 under it.
UNDERCUT = [(0, 0), (0, 10), (-10, 10), (-10, 6), (-6, 6), (-6, 4), (-14, 4), (-14, 10), (-30, 10), (-30, 0)]
OVERHANG_Z, OVERHANG_TOP = (-10.0, -6.0), 10.0


def test_an_undercut_no_tool_from_outside_can_reach_is_refused(run, tmp_path):
    """Between Z-10 and Z-6 the collar (up to r 10) lies over the pocket: a turning tool comes
    from outside along X and cannot be under it without its holder going through the collar.
    The engine's finish runs X12/X8 from Z-10 to Z-6 under the collar instead of refusing."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline(UNDERCUT)
    doc.saveas(tmp_path / "undercut.dxf")
    made = run("import-dxf", tmp_path / "undercut.dxf", "--rough-depth", "1", "--program-name", "UNDERCUT",
               "--machine", "lathe-840d", "--json")
    if made.exit_code == 1:
        assert made.stderr.count("\n") == 1, made.output
        return
    assert made.exit_code == 0, made.output
    program = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--dry-run")
    under = sorted({(start, end) for g, start, end in motions(program.stdout.splitlines())
             for k in range(SAMPLES_PER_MOVE + 1)
             if OVERHANG_Z[0] + INSIDE_MM < start[0] + (end[0] - start[0]) * k / SAMPLES_PER_MOVE
             < OVERHANG_Z[1] - INSIDE_MM
             and start[1] + (end[1] - start[1]) * k / SAMPLES_PER_MOVE < OVERHANG_TOP - INSIDE_MM})
    assert under == []
