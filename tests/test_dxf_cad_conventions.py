"""Turned parts as CAD draws them (issue 27): a half-profile with a vertical axis (the revolve
convention of OpenSCAD and FreeCAD), a layer the entities use but the LAYER table lacks, a
program name that fits the lathe's dialect.

Real drawings: the OpenSCAD chess pieces of tests/data/dxf (scadchess_*): the pawn's ball top
becomes the front, a dome on the axis. Built here with ezdxf (no public real file was found):
a FreeCAD-style open half-profile with an arc, and a drawing whose part is on a layer missing
from the LAYER table (as some exporters write them; legal DXF)."""
from __future__ import annotations

import math

import ezdxf
import pytest
from helpers.drawings import DXF
from helpers.drawn_parts import HALF_PROFILE, outline_drawing
from helpers.outcomes import job_count, made, one_line_refusal

from engine.drawings.drawing import read_drawing
from engine.drawings.geometry import Arc
from engine.drawings.profile import sweep
from engine.drawings.read import DxfError


def job_passes_every_check(run, *args) -> dict:
    """import-dxf, then instantiate (verifier, gouge, finish, material checks) and simulate."""
    job = made(run("import-dxf", *args, "--json"))
    program = made(run("instantiate", "--job", job["job_id"], "--json"))
    assert not program["unverified"]
    simulated = run("simulate", "--program", program["program_id"])
    assert simulated.exit_code == 0, simulated.output
    return job


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@pytest.mark.parametrize(("name", "speed"), [("scadchess_pawn_profile_R2007.dxf", "800"),
                                             ("scadchess_queen_profile_R2007.dxf", "500")])
def test_openscad_chess_pieces_become_jobs_that_pass_every_check(run, name, speed):
    job = job_passes_every_check(run, DXF / name, "--rough-depth", "2", "--speed", speed,
                                 "--program-name", "CHESS_PIECE")
    assert any("the axis is vertical" in note and "+Y" in note for note in job["notes"])


def test_the_pawn_s_ball_top_is_the_front_on_the_axis():
    doc = ezdxf.readfile(DXF / "scadchess_pawn_profile_R2007.dxf")
    points = [p for e in doc.modelspace().query("LWPOLYLINE") for p in e.get_points("xy")]
    top = max(y for _, y in points)
    profile = read_drawing(DXF / "scadchess_pawn_profile_R2007.dxf").profile
    z_min, z_max, r_min, r_max = profile.bounds
    assert (z_min, z_max) == pytest.approx((min(y for _, y in points), top))
    assert (r_min, r_max) == pytest.approx((0.0, max(x for x, _ in points)))
    assert any(abs(s.start[0] - z_max) < 1e-9 and s.start[1] == 0 for s in profile.segments)   # front on the axis


def freecad_sketch(path, layer="Sketch"):
    """An open half-profile as a FreeCAD sketch revolved about its vertical axis: from the axis
    at the bottom (Y 0) out to R10, up to Y 30, then a dome R10 about (0, 30) back to the axis."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.layers.add(layer)
    msp = doc.modelspace()
    msp.add_line((0, 0), (10, 0), dxfattribs={"layer": layer})
    msp.add_line((10, 0), (10, 30), dxfattribs={"layer": layer})
    msp.add_arc((0, 30), 10, 0, 90, dxfattribs={"layer": layer})
    doc.saveas(path)
    return path


def test_a_vertical_half_profile_is_turned_into_z_x_with_its_arcs(tmp_path):
    drawing = read_drawing(freecad_sketch(tmp_path / "dome.dxf"))
    assert drawing.profile.bounds == pytest.approx((0, 40, 0, 10))
    arcs = [s for s in drawing.profile.segments if isinstance(s, Arc)]
    assert len(arcs) == 1 and arcs[0].centre == pytest.approx((30, 0))
    assert sweep(arcs[0]) == pytest.approx(math.pi / 2)   # the dome, not the rest of its circle
    assert drawing.profile.start == pytest.approx((40, 0))   # turning starts at the front, on the axis


def test_a_vertical_half_profile_becomes_a_job(run, tmp_path):
    job_passes_every_check(run, freecad_sketch(tmp_path / "dome.dxf"), "--rough-depth", "1",
                           "--program-name", "DOME")


def test_an_outline_turning_about_another_vertical_line_is_refused_saying_so(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(5, 20), (5, -20), (15, -20), (15, 10), (12, 20)], close=True)
    doc.saveas(tmp_path / "off.dxf")
    with pytest.raises(DxfError, match="the axis looks vertical: rotate the drawing") as caught:
        read_drawing(tmp_path / "off.dxf")
    assert "drawing X 5" in str(caught.value)


def missing_layer_drawing(path, layer="LaserWeb"):
    """The stepped shaft's half-profile on a layer no LAYER table entry declares."""
    doc = ezdxf.new("R12")
    msp = doc.modelspace()
    for start, end in zip(HALF_PROFILE, HALF_PROFILE[1:]):
        msp.add_line(start, end, dxfattribs={"layer": layer})
    doc.saveas(path)
    assert layer == "0" or layer not in ezdxf.readfile(path).layers
    return path


def test_a_layer_missing_from_the_layer_table_can_be_named(run, tmp_path):
    path = missing_layer_drawing(tmp_path / "shaft.dxf")
    assert read_drawing(path, "laserweb").profile.bounds == pytest.approx((-40, 0, 0, 14))
    with pytest.raises(DxfError, match=r"'outline' is not in the drawing; its layers are .*'LaserWeb'"):
        read_drawing(path, "outline")
    job_passes_every_check(run, path, "--profile-layer", "LaserWeb", "--rough-depth", "1", "--program-name", "SHAFT")


def test_a_long_file_name_is_no_reason_to_refuse_on_the_iso_lathe(run, tmp_path):
    """ISO: the program is its O number (the job's, O0001 … O8999), the name a comment; 840D: the
    name is the program, so one that does not fit is refused there."""
    path = missing_layer_drawing(tmp_path / "a_drawing_file_name_over_24_characters.dxf", "0")
    before = job_count(run.url)
    on_840d = one_line_refusal(run("import-dxf", path, "--rough-depth", "1", "--machine", "lathe-840d"))
    assert "840D lathe the name is the program" in on_840d and "--program-name" in on_840d
    assert "at most 24 characters" in on_840d and job_count(run.url) == before
    job = made(run("import-dxf", path, "--rough-depth", "1", "--json"))
    number = (job["job_id"] - 1) % 8999 + 1
    program = made(run("instantiate", "--job", job["job_id"], "--json"))
    assert program["name"] == f"DXF_O{number:04d}"
    text = run("programs", "show", program["program_id"]).stdout
    assert f"O{number:04d} (DXF_O{number:04d})" in text and "a_drawing_file_name_over_24_characters" in text
    assert any(f"O{number:04d}" in note and "O number" in note for note in job["notes"]), job["notes"]


def inch_hex_bolt(path):
    """A hex bolt's side view across the head's corners, in inches, as a CAD user draws it (built
    after a public multi-view drawing whose repository names no licence): the head's 30° corner
    chamfers end its outline ±0.866 at X 1.367, the hexagon's edges (±e/4 = ±0.433) start at
    X 1.375; the shank's edge ±0.51 starts under the chamfer below the head, at X 1.973."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 1
    msp = doc.modelspace()
    for sign in (1, -1):
        upper = [(1.300, 0.0), (1.300, 0.75), (1.367, 0.866), (1.972, 0.866), (1.972, 0.54), (2.002, 0.51)]
        msp.add_lwpolyline([(x, sign * y) for x, y in upper])
        msp.add_line((1.973, sign * 0.51), (4.973, sign * 0.51))
        msp.add_line((4.973, sign * 0.51), (4.973, 0.0))
        msp.add_line((1.375, sign * 0.433), (1.972, sign * 0.433))
    msp.add_line((1.2, 0), (5.1, 0), dxfattribs={"linetype": "CENTER"})
    doc.saveas(path)
    return path


def test_a_hex_bolt_is_refused_for_its_hexagon_not_for_a_bore(tmp_path):
    with pytest.raises(DxfError) as caught:
        read_drawing(inch_hex_bolt(tmp_path / "bolt.dxf"))
    message = str(caught.value)
    assert "hexagon seen across its corners" in message and "bore" not in message
    assert f"±{0.433 * 25.4:.3f}" in message and f"±{0.866 * 25.4:.3f}" in message


def test_a_drawing_either_axis_could_turn_is_read_seed_000_and_the_report_says_so(tmp_path):
    """A rectangle from the origin right and up: a Ø100 disc 20 long about drawing Y 0, or a Ø40
    bar 50 long about drawing X 0. The seed-000 reading stands; a note names the other."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(0, 0), (20, 0), (20, 50), (0, 50)], close=True)
    doc.saveas(tmp_path / "either.dxf")
    drawing = read_drawing(tmp_path / "either.dxf")
    assert drawing.profile.bounds == pytest.approx((0, 20, 0, 50))
    assert any("if that is its axis, rotate the drawing" in note for note in drawing.notes)
    shaft = read_drawing(outline_drawing(tmp_path / "shaft.dxf"))   # drawn left of X 0: no doubt
    assert not any("rotate the drawing" in note for note in shaft.notes)
