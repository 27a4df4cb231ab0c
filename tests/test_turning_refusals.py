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
from lathe_programs import motions, operation_lines

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


def test_the_cli_refuses_a_ring_in_one_line_and_stores_nothing(run, tmp_path):
    with psycopg.connect(run.url) as conn:
        before = conn.execute("SELECT count(*) FROM job").fetchone()[0]
    made = run("import-dxf", drawn(tmp_path / "ring.dxf", RING, closed=True), "--rough-depth", "1",
               "--program-name", "RING", "--machine", "lathe-840d", "--json")
    assert made.exit_code == 1 and made.stderr.count("\n") == 1, made.output
    message = json.loads(made.stderr)["error"]
    assert f"bore Ø{2 * BORE:g}" in message and "internal turning is not supported" in message
    with psycopg.connect(run.url) as conn:
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
