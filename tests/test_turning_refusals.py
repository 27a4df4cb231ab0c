"""What a turning job refuses because it would be a different part: a section off the axis (a
ring, a bore: internal turning is not supported), an undercut no tool from outside reaches,
and a drawing without units whose header says imperial. Each drawing is built here with ezdxf
in the seed-000 convention (drawing X = Z, drawing Y = radius); the refusals must name the
diameter or Z range the test drew, and the neighbours of each refused shape (a solid section,
a plain groove, a drawing with its units) must still become the part drawn."""
from __future__ import annotations

import json

import ezdxf
import psycopg
import pytest
from helpers.drawn_parts import DRAWN_DIAMETERS, drawing
from helpers.lathe_programs import INSIDE_MM, SAMPLES_PER_MOVE, finish_diameters, motions, operation_lines
from helpers.outcomes import counts

from engine.drawings.drawing import read_drawing
from engine.drawings.read import DxfError
from engine.errors import EngineError
from engine.turning.job_params import ProfileOptions, turning_job
from engine.turning.model import job_passes

INCH_MM = 25.4
ROUGH = ProfileOptions(rough_depth=1.0)
# A ring Ø70/Ø50 × 20 as its section: the rectangle between the bore and the outside.
RING = [(0, 25), (-20, 25), (-20, 35), (0, 35)]
BORE, OUTSIDE = 25.0, 35.0
# A disc Ø70 × 20 as its section: the same rectangle down to the axis.
DISC = [(0, 0), (-20, 0), (-20, 35), (0, 35)]
# A bush Ø40 × 30 with a blind bore Ø12 × 10 from the face, as its section touching the axis.
BLIND = [(0, 6), (-10, 6), (-10, 0), (-30, 0), (-30, 20), (0, 20)]
# Half-profiles: a collar Ø20 overhanging a pocket r 4…6 between Z-10 and Z-6; the same part
# with a plain groove r 4 from Z-14 to Z-6 (the collar face at Z-6 radial: reachable).
UNDERCUT = [(0, 0), (0, 10), (-10, 10), (-10, 6), (-6, 6), (-6, 4), (-14, 4), (-14, 10), (-30, 10), (-30, 0)]
GROOVE = [(0, 0), (0, 10), (-6, 10), (-6, 4), (-14, 4), (-14, 10), (-30, 10), (-30, 0)]
SHAFT = [(0, 0), (0, 8), (-12, 8), (-12, 12), (-35, 12), (-35, 0)]


def drawn(path, points, closed: bool = False, **header):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    for name, value in header.items():
        doc.header[f"${name}"] = value
    doc.modelspace().add_lwpolyline(points, close=closed)
    doc.saveas(path)
    return path


def passes_of(path):
    """The job's passes as import-dxf plans them (EngineError if the job is refused)."""
    job = turning_job(read_drawing(path), "lathe-840d", "turning_840d", 1, ROUGH, None, "PART")
    return job_passes(job.params, job.module_params)


def refusal(path) -> str:
    with pytest.raises(EngineError) as refused:
        passes_of(path)
    message = str(refused.value)
    assert "\n" not in message
    return message


def test_a_ring_drawn_as_its_section_is_refused_naming_its_bore(tmp_path):
    message = refusal(drawn(tmp_path / "ring.dxf", RING, closed=True))
    assert f"bore Ø{2 * BORE:g}" in message and "internal turning is not supported" in message
    assert "Z-20 … Z0" in message and "half-profile" in message   # where, and what to draw instead


def test_a_blind_bore_in_a_closed_section_is_refused_with_its_diameter_and_depth(tmp_path):
    message = refusal(drawn(tmp_path / "blind.dxf", BLIND, closed=True))
    assert f"bore Ø{2 * BLIND[0][1]:g} at Z{BLIND[1][0]:g} … Z0" in message


def test_a_closed_section_down_to_the_axis_is_a_solid_part_and_turned(tmp_path):
    passes = passes_of(drawn(tmp_path / "disc.dxf", DISC, closed=True))
    finish_radii = {move.x / 2.0 for one in passes[2] for move in one if move.kind == "feed"}
    assert OUTSIDE in finish_radii


def test_an_undercut_is_refused_naming_its_z_range_and_the_collar(tmp_path):
    message = refusal(drawn(tmp_path / "undercut.dxf", UNDERCUT))
    collar_face, pocket_end = UNDERCUT[3][0], UNDERCUT[5][0]
    assert f"undercut at Z{collar_face:g} … Z{pocket_end:g}" in message
    assert f"radius {UNDERCUT[5][1]:g} … {UNDERCUT[4][1]:g}" in message and "external tool cannot reach" in message


def test_a_plain_groove_of_the_same_depth_is_no_undercut(tmp_path):
    passes = passes_of(drawn(tmp_path / "groove.dxf", GROOVE))
    finish = [move for one in passes[2] for move in one]
    assert any(move.kind == "feed" and move.x / 2.0 == GROOVE[3][1] for move in finish)


def test_a_job_edited_in_sql_into_an_undercut_is_refused_at_instantiation(tmp_path):
    job = turning_job(read_drawing(drawn(tmp_path / "groove.dxf", GROOVE)), "lathe-840d", "turning_840d", 1,
                      ROUGH, None, "PART")
    edited = turning_job(read_drawing(drawn(tmp_path / "undercut.dxf", UNDERCUT)), "lathe-840d",
                         "turning_840d", 1, ROUGH, None, "PART").params["profile"]
    job.params["profile"] = edited
    with pytest.raises(EngineError, match="undercut at Z-10 … Z-6"):
        job_passes(job.params, job.module_params)


def imperial(path, **header):
    """SHAFT drawn in inches (each mm number divided by 25.4), the header as given."""
    return drawn(path, [(z / INCH_MM, r / INCH_MM) for z, r in SHAFT], **header)


def test_a_unitless_drawing_whose_header_says_english_is_refused_asking_for_the_unit(tmp_path):
    with pytest.raises(DxfError) as refused:
        read_drawing(imperial(tmp_path / "english.dxf", INSUNITS=0, MEASUREMENT=0))
    assert "$MEASUREMENT 0" in str(refused.value) and "$INSUNITS 1 = inches" in str(refused.value)


def test_a_unitless_metric_drawing_is_taken_as_millimetres(tmp_path):
    drawing = read_drawing(drawn(tmp_path / "metric.dxf", SHAFT, INSUNITS=0, MEASUREMENT=1))
    assert drawing.profile.bounds[3] == pytest.approx(12.0)
    assert any("taken as millimetres" in note for note in drawing.notes)


def test_dimensions_written_in_mm_outweigh_the_english_measurement(tmp_path):
    drawing = read_drawing(drawn(tmp_path / "mm.dxf", SHAFT, INSUNITS=0, MEASUREMENT=0, DIMPOST="<>mm"))
    assert drawing.profile.bounds[3] == pytest.approx(12.0)
    assert any("$DIMPOST" in note for note in drawing.notes)


def test_a_drawing_in_inches_is_scaled_whatever_its_measurement(tmp_path):
    drawing = read_drawing(imperial(tmp_path / "inch.dxf", INSUNITS=1, MEASUREMENT=0))
    assert drawing.profile.bounds[3] == pytest.approx(12.0)


def test_the_cli_refuses_a_ring_in_one_line_and_stores_nothing(read_only_run, tmp_path):
    with psycopg.connect(read_only_run.url) as conn:
        before = conn.execute("SELECT count(*) FROM job").fetchone()[0]
    made = read_only_run("import-dxf", drawn(tmp_path / "ring.dxf", RING, closed=True), "--rough-depth", "1",
                         "--program-name", "RING", "--machine", "lathe-840d", "--json")
    assert made.exit_code == 1 and made.stderr.count("\n") == 1, made.output
    message = json.loads(made.stderr)["error"]
    assert f"bore Ø{2 * BORE:g}" in message and "internal turning is not supported" in message
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM job").fetchone()[0] == before


def test_the_disc_job_finishes_its_outside_diameter(run, tmp_path):
    made = run("import-dxf", drawn(tmp_path / "disc.dxf", DISC, closed=True), "--rough-depth", "1",
               "--program-name", "DISC", "--machine", "lathe-840d", "--json")
    assert made.exit_code == 0, made.output
    program = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--dry-run")
    finish = operation_lines(program.stdout.splitlines(), 2)
    along_z = {2 * start[1] for g, start, end in motions(finish)
               if g == 1 and start[1] == end[1] and start[0] != end[0]}
    assert along_z == {2 * OUTSIDE}


def ring_section_off_the_axis(msp) -> None:
    """A ring Ø70/Ø50 × 20 as its section in the seed-000 convention (radius = drawing Y): the closed
    rectangle between the bore and the outside, not touching the axis."""
    msp.add_lwpolyline([(0, 25), (-20, 25), (-20, 35), (0, 35)], close=True)


def test_a_ring_drawn_as_its_section_is_not_turned_as_a_solid_bar(read_only_run, tmp_path):
    """A closed profile that stays 25 mm off the axis is a ring: its bore Ø50 cannot be turned from
    outside. The job turns the outside Ø70 only and says nothing of the bore — a solid disc where
    the drawing has a ring."""
    path = tmp_path / "ring.dxf"
    drawing(path, ring_section_off_the_axis)
    before = counts(read_only_run.url)
    made = read_only_run("import-dxf", path, "--rough-depth", "1", "--program-name", "RING", "--machine",
                         "lathe-840d", "--json")
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and counts(read_only_run.url) == before


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
