"""Full side views from real CAD (issue 17): a turned part drawn whole about a centre line
becomes its upper half-profile; what a lathe cannot make from outside is refused by name.

Every expected number is read from the drawing here with ezdxf (extents, the centre line,
the hatching), and the programs are checked against the drawn lines by sampling, not by
the engine's own geometry."""
from __future__ import annotations

import json
import math
import shutil

import ezdxf
import ezdxf.bbox
import ezdxf.path
import pytest
from helpers.drawings import DXF
from helpers.drawn_parts import AXIS_Y, SHAFT, outline_drawing
from helpers.lathe_programs import distance_to_chord, motions, operation_lines

from engine.drawings.drawing import read_drawing
from engine.drawings.read import DxfError
from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions
from importers.dxf import import_dxf

FLATTENING_MM = 0.0005
ON_DRAWING_MM = 0.01       # a finish end point this close to a drawn line is on it
GOUGE_MM = 0.01            # the depth engine.turning.gouge allows a finish on the profile
STEP_WINDOW_MM = 0.02      # at a radial step, the outline's radius is the lower side's


def entities(name: str, layer: str):
    return [e for e in ezdxf.readfile(DXF / name).modelspace() if e.dxf.layer == layer]


def layer_extents(name: str, layer: str):
    box = ezdxf.bbox.extents(entities(name, layer))
    return box.extmin, box.extmax


def centre_line_y(name: str) -> float:
    """The drawing's horizontal centre line: the LINE on a layer with a dash-dot linetype."""
    doc = ezdxf.readfile(DXF / name)
    dash_dot = {layer.dxf.name for layer in doc.layers if "DASHDOT" in (layer.dxf.linetype or "").upper()}
    (line,) = [e for e in doc.modelspace() if e.dxftype() == "LINE" and e.dxf.layer in dash_dot]
    assert line.dxf.start.y == pytest.approx(line.dxf.end.y)
    return line.dxf.start.y


def upper_polylines(path, layer: str, axis_y: float) -> list[list[tuple[float, float]]]:
    """Every line and arc of the layer as (z, radius above the centre line) chords."""
    found = []
    for entity in ezdxf.readfile(path).modelspace():
        if entity.dxf.layer == layer and entity.dxftype() in ("LINE", "ARC", "LWPOLYLINE", "CIRCLE"):
            points = ezdxf.path.make_path(entity).flattening(FLATTENING_MM)
            found.append([(p.x, p.y - axis_y) for p in points])
    return found


def outline_radius(z: float, polylines) -> float:
    """The highest drawn radius at z (the side view's outline), the lower side at a step."""
    def top(at: float) -> float:
        return max((a[1] + (b[1] - a[1]) * (at - a[0]) / (b[0] - a[0])
                    for line in polylines for a, b in zip(line, line[1:])
                    if min(a[0], b[0]) <= at <= max(a[0], b[0]) and a[0] != b[0]), default=0.0)
    return min(top(z - STEP_WINDOW_MM), top(z), top(z + STEP_WINDOW_MM))


def distance_to_lines(point, polylines) -> float:
    return min(distance_to_chord(point, a, b) for line in polylines for a, b in zip(line, line[1:]))


def sampled(start, end, step: float = 0.05):
    count = max(1, math.ceil(math.dist(start, end) / step))
    return [(start[0] + (end[0] - start[0]) * k / count, start[1] + (end[1] - start[1]) * k / count)
            for k in range(count + 1)]


def check_program_against_the_drawing(lines: list[str], polylines, z_span) -> None:
    """The finish (operation 2) ends every move on a drawn line and reaches the outline's
    largest radius; no straight move of rough or finish lies deeper inside the outline than
    the finish's own tolerance."""
    z_min, z_max = z_span
    finish = [(g, start, end) for g, start, end in motions(operation_lines(lines, 2)) if g in (1, 2, 3)]
    assert finish
    for _, _, end in finish:
        assert distance_to_lines(end, polylines) <= ON_DRAWING_MM, end
    largest = max(point[1] for line in polylines for point in line)
    assert max(end[1] for _, _, end in finish) == pytest.approx(largest, abs=0.001)
    assert len(motions(operation_lines(lines, 1))) > 10   # roughing is there to be checked
    for number in (1, 2):
        for g, start, end in motions(operation_lines(lines, number)):
            if g not in (0, 1):
                continue
            for z, r in sampled(start, end):
                if z_min + STEP_WINDOW_MM < z < z_max - STEP_WINDOW_MM:
                    assert r >= outline_radius(z, polylines) - GOUGE_MM, (number, g, start, end, z, r)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_qcad_screw_becomes_its_upper_half_and_a_checked_job(conn):
    name = "qcad_screw_R2007.dxf"
    axis_y = centre_line_y(name)
    low, high = layer_extents(name, "0")
    drawing = read_drawing(DXF / name)
    z_min, z_max, _, r_max = drawing.profile.bounds
    assert (z_min, z_max) == pytest.approx((low.x, high.x))
    assert r_max == pytest.approx(high.y - axis_y)              # the extent above the centre line
    assert drawing.profile.closed_by_axis
    assert any("side view" in note and "centre line" in note for note in drawing.notes)
    # The head's end face is drawn down to the screwdriver slot only: said, not made.
    face_lines = [e for e in entities(name, "0") if e.dxftype() == "LINE" and e.dxf.start.x == e.dxf.end.x == low.x]
    slot = min(abs(point.y - axis_y) for line in face_lines for point in (line.dxf.start, line.dxf.end))
    assert any(f"end face at Z{low.x:.3f} is drawn down to radius {slot:.3f} only" in note for note in drawing.notes)
    report = import_dxf(conn, DXF / name, "lathe-iso", ProfileOptions(rough_depth=1.0), program_name="SCREW")
    lines = instantiate_job(conn, report.job_id).lines          # the engine's gouge and finish checks run here
    check_program_against_the_drawing(lines, upper_polylines(DXF / name, "0", axis_y), (low.x, high.x))


def test_the_din931_bolt_is_refused_for_its_hexagon_head():
    name = "qcad_M4x25_DIN931_f_R2010.dxf"
    low, high = layer_extents(name, "outline")
    half_across_corners = (high.x - low.x) / 2.0     # the head is the widest part: e/2
    with pytest.raises(DxfError) as refused:
        read_drawing(DXF / name)   # layer 0 is empty: 'outline' is taken
    message = str(refused.value)
    assert "not a turned surface" in message and "hexagon" in message and "\n" not in message
    assert f"±{half_across_corners:.3f}" in message and f"±{half_across_corners / 2:.1f}" in message


def test_the_qcad_flange_is_refused_for_its_bore():
    name = "qcad_flange_R2013.dxf"
    (hatch,) = [e for e in ezdxf.readfile(DXF / name).modelspace() if e.dxftype() == "HATCH"]
    axis_y = centre_line_y_of_section(name)
    boundary = [v for path in ezdxf.path.from_hatch(hatch) for v in path.flattening(0.01)]
    bore = 2 * min(abs(v.y - axis_y) for v in boundary)
    with pytest.raises(DxfError) as refused:
        read_drawing(DXF / name)
    message = str(refused.value)
    assert f"bore Ø{bore:.3f}" in message and "internal turning, which is not supported" in message


def centre_line_y_of_section(name: str) -> float:
    """The centre line that runs along the hatched view (the nearest one spanning it)."""
    msp = ezdxf.readfile(DXF / name).modelspace()
    (hatch,) = [e for e in msp if e.dxftype() == "HATCH"]
    box = ezdxf.bbox.extents([hatch])
    lines = [e for e in msp if e.dxftype() == "LINE" and e.dxf.layer == "center"
             and e.dxf.start.y == e.dxf.end.y and min(e.dxf.start.x, e.dxf.end.x) <= box.extmin.x
             and max(e.dxf.start.x, e.dxf.end.x) >= box.extmax.x]
    return min(lines, key=lambda line: abs(line.dxf.start.y - box.extmin.y)).dxf.start.y


@pytest.mark.parametrize("name", ["d2gp_fc_mounting_R12.dxf", "d2gp_fc_mounting_R2013.dxf"])
def test_a_hole_pattern_is_refused_as_a_plate(name):
    circles = [e for e in entities(name, "0") if e.dxftype() == "CIRCLE"]
    with pytest.raises(DxfError) as refused:
        read_drawing(DXF / name)
    message = str(refused.value)
    assert "not a turned part" in message and "plate" in message
    assert f"{len(circles)} separate outline" in message


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_pump_parts_sheet_is_refused_as_a_plate():
    with pytest.raises(DxfError) as refused:
        read_drawing(DXF / "d2gp_pumpenteile_R2000.dxf")
    message = str(refused.value)
    assert "not a turned part" in message and "plate" in message and "inside another" in message


def whole_shaft(path, *, bore_depth: float | None = None) -> None:
    """The shaft's full outline, the lines across at its shoulders, a CENTER centre line,
    hatching of the whole section, a dimension, a text and a cross hole Ø4 at Z -25 in hidden
    (DASHED) lines; with bore_depth, also a bore Ø6 that deep from the face, in hidden lines."""
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("Mittellinie", linetype="CENTER")
    msp = doc.modelspace()
    upper = [(z, AXIS_Y + r) for z, r in SHAFT]
    lower = [(z, AXIS_Y - r) for z, r in reversed(SHAFT)]
    msp.add_lwpolyline(upper + lower, close=True)
    for z, radius in ((-12, 8), (-35, 10)):   # where a diameter meets a shoulder face
        msp.add_line((z, AXIS_Y - radius), (z, AXIS_Y + radius))
    msp.add_line((5, AXIS_Y), (-55, AXIS_Y), dxfattribs={"layer": "Mittellinie"})
    hatch = msp.add_hatch()
    hatch.paths.add_polyline_path(upper + lower, is_closed=True)
    msp.add_linear_dim(base=(0, AXIS_Y + 20), p1=(0, AXIS_Y + 8), p2=(-50, AXIS_Y + 10)).render()
    msp.add_text("SHAFT 1", dxfattribs={"height": 3}).set_placement((-40, AXIS_Y + 25))
    for z in (-23, -27):
        msp.add_line((z, AXIS_Y - 12), (z, AXIS_Y + 12), dxfattribs={"linetype": "DASHED"})
    for side in ((3, -3) if bore_depth else ()):
        msp.add_line((0, AXIS_Y + side), (-bore_depth, AXIS_Y + side), dxfattribs={"linetype": "DASHED"})
    doc.saveas(path)


def test_a_whole_side_view_becomes_exactly_its_upper_half(tmp_path):
    whole_shaft(tmp_path / "shaft.dxf")
    drawing = read_drawing(tmp_path / "shaft.dxf")
    corners = [drawing.profile.segments[0].start] + [s.end for s in drawing.profile.segments]
    assert [coordinate for corner in corners for coordinate in corner] == pytest.approx(
        [coordinate for corner in SHAFT for coordinate in corner])
    assert drawing.profile.closed_by_axis
    assert any("hidden" in note for note in drawing.notes)


def test_a_bore_shown_by_hidden_lines_is_refused(tmp_path):
    whole_shaft(tmp_path / "bored.dxf", bore_depth=20)
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / "bored.dxf")
    message = str(refused.value)
    assert "hidden lines show a bore Ø6.000 from Z-20.000 to Z0.000" in message
    assert "internal turning, which is not supported" in message


def test_a_whole_side_view_makes_a_checked_job(conn, tmp_path):
    whole_shaft(tmp_path / "shaft.dxf")
    report = import_dxf(conn, tmp_path / "shaft.dxf", "lathe-840d", ProfileOptions(rough_depth=1.5),
                        program_name="SHAFT")
    lines = instantiate_job(conn, report.job_id).lines
    drawn = [[(z, r) for z, r in SHAFT]]
    assert any("side view" in note for note in report.notes)
    finish = [end for g, _, end in motions(operation_lines(lines, 2)) if g == 1]
    for corner in SHAFT:
        assert min(math.dist(corner, end) for end in finish) <= ON_DRAWING_MM, corner
    check_program_against_the_drawing(lines, drawn, (-50, 0))


def test_the_profile_layer_is_chosen_when_layer_0_is_empty():
    name = "d2g_132_R14.dxf"
    (layer,) = {e.dxf.layer for e in ezdxf.readfile(DXF / name).modelspace()}
    low, high = layer_extents(name, layer)
    drawing = read_drawing(DXF / name)
    assert drawing.profile.bounds == pytest.approx((low.x, high.x, low.y, high.y))
    assert any("layer 0 is empty" in note and repr(layer) in note for note in drawing.notes)


def test_two_layers_that_could_be_the_part_are_refused_naming_both(tmp_path):
    shutil.copy(DXF / "d2g_132_R14.dxf", tmp_path / "one.dxf")
    doc = ezdxf.readfile(tmp_path / "one.dxf")
    doc.layers.add("Kontur")
    for entity in list(doc.modelspace()):
        copy = entity.copy()
        copy.dxf.layer = "Kontur"
        doc.modelspace().add_entity(copy)
    doc.saveas(tmp_path / "two.dxf")
    with pytest.raises(DxfError) as refused:
        read_drawing(tmp_path / "two.dxf")
    message = str(refused.value)
    assert "'81' and 'Kontur'" in message and "--profile-layer" in message


def upright_pin(path) -> None:
    """A pin Ø16 drawn standing up about a vertical centre line at X 40 on a layer named 'axis':
    its face at Y 0 rounded into its diameter by R2 fillets, its foot at Y -40."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.layers.add("axis")
    msp = doc.modelspace()
    msp.add_line((34, 0), (46, 0))
    msp.add_arc((46, -2), 2, 0, 90)
    msp.add_arc((34, -2), 2, 90, 180)
    msp.add_line((48, -2), (48, -40))
    msp.add_line((48, -40), (32, -40))
    msp.add_line((32, -40), (32, -2))
    msp.add_line((40, 3), (40, -43), dxfattribs={"layer": "axis"})
    doc.saveas(path)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_an_upright_side_view_is_turned_to_lie_along_z(conn, tmp_path):
    upright_pin(tmp_path / "pin.dxf")
    profile = read_drawing(tmp_path / "pin.dxf").profile
    fillet, side = profile.segments
    assert fillet.start == pytest.approx((0, 6)) and fillet.end == pytest.approx((-2, 8))
    assert fillet.centre == pytest.approx((-2, 6))
    # The fillet bulges away from its centre: halfway along it lies at 45° on the R2 circle.
    direction = 1.0 if fillet.ccw else -1.0
    halfway = direction * math.pi / 4      # it starts at angle 0 about its centre
    assert (-2 + 2 * math.cos(halfway), 6 + 2 * math.sin(halfway)) == pytest.approx(
        (-2 + 2 * math.sqrt(0.5), 6 + 2 * math.sqrt(0.5)))
    assert (side.start, side.end) == (pytest.approx((-2, 8)), pytest.approx((-40, 8)))
    report = import_dxf(conn, tmp_path / "pin.dxf", "lathe-iso", ProfileOptions(rough_depth=1.0), program_name="PIN")
    lines = instantiate_job(conn, report.job_id).lines
    drawn = [[(y, x - 40) for x, y in line] for line in upper_polylines_xy(tmp_path / "pin.dxf")]
    check_program_against_the_drawing(lines, drawn, (-40, 0))


def upper_polylines_xy(path) -> list[list[tuple[float, float]]]:
    """The layer-0 lines and arcs as drawn (x, y) chords."""
    return [[(p.x, p.y) for p in ezdxf.path.make_path(e).flattening(FLATTENING_MM)]
            for e in ezdxf.readfile(path).modelspace() if e.dxf.layer == "0"]


def test_the_import_report_says_what_was_read_in_text_and_json(run, tmp_path):
    text = run("import-dxf", DXF / "qcad_screw_R2007.dxf", "--rough-depth", "1")
    assert text.exit_code == 0, text.output
    assert any(line.startswith("  note: layer 0 is a side view") for line in text.stderr.splitlines())
    outline_drawing(tmp_path / "shaft.dxf")
    made = run("import-dxf", tmp_path / "shaft.dxf", "--rough-depth", "1", "--program-name", "SHAFT", "--json")
    assert made.exit_code == 0, made.output
    notes = json.loads(made.stdout)["notes"]
    assert any("layer 0 is empty" in note and "'outline'" in note for note in notes)


def test_a_whole_view_without_a_centre_line_is_halved_at_its_symmetry(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline(SHAFT + [(z, -r) for z, r in reversed(SHAFT)], close=True)
    doc.saveas(tmp_path / "plain.dxf")
    drawing = read_drawing(tmp_path / "plain.dxf")
    corners = [drawing.profile.segments[0].start] + [s.end for s in drawing.profile.segments]
    assert [coordinate for corner in corners for coordinate in corner] == pytest.approx(
        [coordinate for corner in SHAFT for coordinate in corner])
    assert any("line of symmetry at drawing Y 0.000" in note for note in drawing.notes)
