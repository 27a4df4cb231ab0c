"""Lines a side view shows inside its outline (issue 17, adversary review adv2): left out only
when recognised as a kind that does not change the turned surface (an edge across the part, a
thread's root, an end face, an open end's slot); a bore drawn in solid lines or any line the
reader cannot place is refused, nothing made. Every drawing is built here with ezdxf; thread
diameters come from ISO 68-1."""
from __future__ import annotations

import json

import ezdxf
import pytest
from helpers.drawn_parts import AXIS_Y, DRAWN_DIAMETERS, SHAFT, drawing
from helpers.lathe_programs import finish_diameters
from helpers.outcomes import counts

from engine.drawings.drawing import read_drawing
from engine.drawings.read import DxfError

# An M16×2 thread on the shaft's Ø16 from the face to Z -10: its root (minor) diameter by ISO 68-1,
# d3 = d - 1.2269 P, drawn as thin lines under the outline, and its end as a line across.
THREAD_D, THREAD_P, THREAD_END = 16.0, 2.0, -10.0


def shaft_with_inner_lines(path, extra=None) -> str | None:
    """The shaft drawn whole with the lines a side view shows inside it (its thread's roots and
    end, its shoulders' edges) and, with `extra(msp)`, one line more."""
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("Mittellinie", linetype="CENTER")
    msp = doc.modelspace()
    msp.add_lwpolyline([(z, AXIS_Y + r) for z, r in SHAFT] + [(z, AXIS_Y - r) for z, r in reversed(SHAFT)], close=True)
    root = (THREAD_D - 1.2269 * THREAD_P) / 2
    for side in (root, -root):
        msp.add_line((0, AXIS_Y + side), (THREAD_END, AXIS_Y + side))
    msp.add_line((THREAD_END, AXIS_Y - THREAD_D / 2), (THREAD_END, AXIS_Y + THREAD_D / 2))
    for z, radius in ((-12, 8), (-35, 10)):
        msp.add_line((z, AXIS_Y - radius), (z, AXIS_Y + radius))
    msp.add_line((5, AXIS_Y), (-55, AXIS_Y), dxfattribs={"layer": "Mittellinie"})
    handle = extra(msp).dxf.handle if extra else None
    doc.saveas(path)
    return handle


def test_thread_roots_and_edges_inside_a_side_view_are_left_out_by_kind(tmp_path):
    """The lines a side view shows inside a solid part do not change the turned surface: the
    profile is the drawn outline, and the note says which kinds of line were left out."""
    shaft_with_inner_lines(tmp_path / "threaded.dxf")
    drawing = read_drawing(tmp_path / "threaded.dxf")
    corners = [drawing.profile.segments[0].start] + [s.end for s in drawing.profile.segments]
    assert [c for corner in corners for c in corner] == pytest.approx([c for corner in SHAFT for c in corner])
    assert any("thread roots: 2" in note and "edges across the part: 3" in note for note in drawing.notes)


UNPLACED_LINES = {   # a line inside the outline that could bound a cavity, not from an end face
    "slanted": lambda msp: msp.add_line((-20, AXIS_Y + 2), (-30, AXIS_Y - 2)),
    "deep_along_the_axis": lambda msp: msp.add_line((-15, AXIS_Y + 4), (-30, AXIS_Y + 4)),
    "across_short_of_the_outline": lambda msp: msp.add_line((-20, AXIS_Y - 4), (-20, AXIS_Y + 4)),
}


@pytest.mark.parametrize("name", UNPLACED_LINES)
def test_a_line_inside_a_side_view_that_is_no_known_kind_is_refused_by_handle(tmp_path, name):
    """A line inside the outline that is no edge across the part, thread root or end face may
    be a cavity's edge in a section drawn without hatching: nothing is made, the line is named."""
    handle = shaft_with_inner_lines(tmp_path / f"{name}.dxf", UNPLACED_LINES[name])
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / f"{name}.dxf")
    message = str(refused.value)
    assert "cannot place" in message and handle in message and "\n" not in message


def test_a_thin_walled_bore_in_solid_lines_is_not_taken_for_a_thread(tmp_path):
    """Lines close under the outline from end face to end face are a tube's bore (Ø15.8 in the
    Ø16 to Ø24 shaft, closer under it than any thread root), however thin its wall: a thread
    ends before the part does."""
    shaft_with_inner_lines(tmp_path / "tube.dxf", lambda msp: [msp.add_line((0, AXIS_Y + side), (-50, AXIS_Y + side))
                                                               for side in (7.9, -7.9)][0])
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / "tube.dxf")
    assert "bore Ø15.800 from Z-50.000 to Z0.000" in str(refused.value)


def test_a_slot_in_one_end_does_not_excuse_a_bore_in_the_other(tmp_path):
    """The face at Z -50 is drawn down to ±1.5 only, a slot 4 deep (left open, said in a note);
    a bore Ø2 × 5 in solid lines in the closed face at Z 0 is narrower than that slot but is
    no part of it: refused."""
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("Mittellinie", linetype="CENTER")
    msp = doc.modelspace()
    upper = [(z, r) for z, r in reversed(SHAFT)]
    msp.add_lwpolyline([(z, AXIS_Y + r) for z, r in [(-50, 1.5)] + upper]
                       + [(z, AXIS_Y - r) for z, r in reversed([(-50, 1.5)] + upper)])
    msp.add_lwpolyline([(-50, AXIS_Y + 1.5), (-46, AXIS_Y + 1.5), (-46, AXIS_Y - 1.5), (-50, AXIS_Y - 1.5)])
    msp.add_lwpolyline([(0, AXIS_Y + 1), (-5, AXIS_Y + 1), (-5, AXIS_Y - 1), (0, AXIS_Y - 1)])
    msp.add_line((5, AXIS_Y), (-55, AXIS_Y), dxfattribs={"layer": "Mittellinie"})
    doc.saveas(tmp_path / "slot_and_bore.dxf")
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / "slot_and_bore.dxf")
    assert "bore Ø2.000 from Z-5.000 to Z0.000" in str(refused.value)


def test_a_root_line_on_one_side_only_is_no_thread(tmp_path):
    """A thread shows its root on both sides of the axis; a line close under the outline above
    the axis only (a flat, a keyway's edge) is not placed: refused by its handle."""
    handle = shaft_with_inner_lines(tmp_path / "one_sided.dxf",
                                    lambda msp: msp.add_line((-15, AXIS_Y + 11), (-30, AXIS_Y + 11)))
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / "one_sided.dxf")
    assert "cannot place" in str(refused.value) and handle in str(refused.value)


BORE_RADIUS = 3.0             # a Ø6 bore along the axis


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


LOWER_HALVES = {   # the lower half as drawn, (z, radius) below the centre line; the upper half is SHAFT
    "collar_shorter_below": [(0, 8), (-12, 8), (-12, 12), (-30, 12), (-30, 10), (-50, 10)],
    "every_radius_smaller_below": [(z, 0.9 * r) for z, r in SHAFT],
}


@pytest.mark.parametrize("name", LOWER_HALVES)
def test_a_side_view_whose_halves_disagree_is_refused(read_only_run, tmp_path, name):
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
    before = counts(read_only_run.url)
    made = read_only_run("import-dxf", path, "--rough-depth", "1", "--program-name", "HALVES", "--machine",
                         "lathe-840d")
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and counts(read_only_run.url) == before
