"""Reading turning drawings (design notes §8): real drawings made by other people, drawings
generated here in the seed-000 convention, and the refusals a user must understand.

Expectations come from the files themselves (counted with ezdxf here), from the
reference (§E: positive bulge = counter-clockwise, extrusion (0,0,-1) flips an arc), from
ezdxf's own bulge geometry, and from the NC programs another lathe tool made of the Emco
drawings (tests/data/nc/emco_from_dxf) — not from the reader's output."""
from __future__ import annotations

import math
import random
import re

import ezdxf
import ezdxf.path
import ezdxf.recover
import pytest
from ezdxf.math import bulge_center
from helpers.drawings import (
    CROSSES,
    DXF,
    EMCO,
    FULL_VIEW,
    HALF_PROFILE,
    INCH,
    NOTHING_ON_0,
    REAL,
    SCATTERED,
    VERTICAL,
    nc_arc_words,
    seed_drawing,
)

from engine.drawings.codes import CodeText, codes_in, layer_codes
from engine.drawings.drawing import read_drawing
from engine.drawings.entities import FLATTEN_TOLERANCE_MM
from engine.drawings.geometry import Arc, Line
from engine.drawings.profile import chain_segments
from engine.drawings.read import DxfError, load_drawing_file

GEOMETRY = {"LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE", "SPLINE", "ELLIPSE"}


def layer0_paths(name: str) -> list:
    """ezdxf paths of the layer-0 geometry in model space, blocks exploded (DXF layer-0 rule)."""
    try:
        doc = ezdxf.readfile(DXF / name)
    except Exception:  # the two damaged files: ezdxf's own tolerant reader
        doc, _ = ezdxf.recover.readfile(DXF / name)
    paths = []

    def visit(entity, layer):
        own = entity.dxf.layer if entity.dxf.layer != "0" else layer
        if entity.dxftype() == "INSERT":
            for part in entity.virtual_entities():
                visit(part, own)
        elif entity.dxftype() in GEOMETRY and own == "0" and not is_mesh(entity):
            paths.append(ezdxf.path.make_path(entity))

    for entity in doc.modelspace():
        visit(entity, entity.dxf.layer)
    return paths


def is_mesh(entity) -> bool:
    return entity.dxftype() == "POLYLINE" and (entity.is_polygon_mesh or entity.is_poly_face_mesh)


def path_length(path) -> float:
    points = list(path.flattening(0.05))  # shares only need about 1 %
    return sum(math.dist(a, b) for a, b in zip(points, points[1:]))


def largest_piece_share(paths) -> float:
    """Length share of the largest set of paths connected end to end (union-find on end
    points): an upper bound for any chain the reader could take as the profile."""
    parent = list(range(len(paths)))

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for i, a in enumerate(paths):
        for j in range(i):
            b = paths[j]
            if any(math.dist(p, q) <= 0.01 for p in (a.start, a.end) for q in (b.start, b.end)):
                parent[root(i)] = root(j)
    lengths = [path_length(p) for p in paths]
    pieces: dict[int, float] = {}
    for i, length in enumerate(lengths):
        pieces[root(i)] = pieces.get(root(i), 0.0) + length
    return max(pieces.values()) / sum(lengths)


def check_fact(name: str, category: str) -> None:
    paths = layer0_paths(name)
    if category == NOTHING_ON_0:
        assert paths == []
    elif category == SCATTERED:
        assert largest_piece_share(paths) < 0.5
    elif category == CROSSES:
        ys = [v.y for v in paths[0].flattening(0.01)]
        assert len(paths) == 1 and min(ys) < 0 < max(ys)
    elif category == VERTICAL:
        check_vertical(name)
    elif category == FULL_VIEW:
        crossing = [p for p in paths if min(p.start.y, p.end.y) < 0 < max(p.start.y, p.end.y)]
        assert len(crossing) >= 2
    else:
        assert paths


def check_vertical(name: str) -> None:
    """Layer 0 empty; the outline right of drawing X 0 and crossing drawing Y 0, with a line along
    its smallest X spanning its height: the edge OpenSCAD's rotate_extrude turns about."""
    doc = ezdxf.readfile(DXF / name)
    assert layer0_paths(name) == []
    points = [v for entity in doc.modelspace().query("LWPOLYLINE")
              for v in ezdxf.path.make_path(entity).flattening(0.01)]
    xs, ys = [v.x for v in points], [v.y for v in points]
    assert min(xs) >= 0 and min(ys) < 0 < max(ys)
    along = [(a, b) for a, b in zip(points, points[1:]) if a.x == b.x == min(xs)]
    assert max(abs(a.y - b.y) for a, b in along) == pytest.approx(max(ys) - min(ys))


@pytest.mark.parametrize("name", sorted(REAL))
def test_every_real_drawing_reads_or_is_refused_with_its_reason(name):
    category, refusal = REAL[name]
    check_fact(name, category)
    if refusal is None:
        drawing = read_drawing(DXF / name)
        assert drawing.profile.closed_by_axis == (category in (HALF_PROFILE, FULL_VIEW))
        if category == VERTICAL:   # turned into Z–X: Z along drawing Y, the radius drawing X from 0
            assert any("the axis is vertical" in note for note in drawing.notes)
            assert drawing.profile.bounds[2] == 0.0
    else:
        with pytest.raises(DxfError, match=re.escape(refusal)) as caught:
            read_drawing(DXF / name)
        assert "\n" not in str(caught.value)


def test_the_list_covers_every_real_drawing():
    assert sorted(p.name for p in DXF.glob("*.dxf")) == sorted(REAL)


def test_a_damaged_file_is_read_tolerantly_and_the_repair_reported():
    with pytest.raises(ezdxf.DXFStructureError):
        ezdxf.readfile(DXF / "ezdxf_AC1003_LINE_Example.dxf")
    loaded = load_drawing_file(DXF / "ezdxf_AC1003_LINE_Example.dxf")
    assert len(loaded.doc.modelspace()) == 22  # 13 LINE + 9 ARC on layer 1, as ezdxf.recover counts
    assert any("ezdxf.recover" in repair for repair in loaded.repairs)


def test_turbocad_outline_is_the_rectangle_not_its_circles():
    doc = ezdxf.readfile(DXF / "d2g_Turbocad_12.5_R14.dxf")
    outline = next(e for e in doc.modelspace() if e.dxftype() == "LWPOLYLINE")
    circles = [e for e in doc.modelspace() if e.dxftype() == "CIRCLE"]
    corners = {(round(x, 6), round(y, 6)) for x, y in outline.get_points("xy")}
    perimeter = 2 * (100 + 50)
    assert outline.closed and perimeter > sum(2 * math.pi * c.dxf.radius for c in circles)
    profile = read_drawing(DXF / "d2g_Turbocad_12.5_R14.dxf").profile
    assert {(round(s.start[0], 6), round(s.start[1], 6)) for s in profile.segments} == corners
    assert profile.bounds == pytest.approx((0, 100, 0, 50))


def drawn_end_points(name: str) -> list[tuple[float, float]]:
    doc = ezdxf.readfile(DXF / name)
    points = []
    for entity in doc.modelspace():
        if entity.dxftype() == "LINE":
            points += [entity.dxf.start, entity.dxf.end]
        else:
            points += [entity.start_point, entity.end_point]
    return [(p.x, p.y) for p in points]


@pytest.mark.parametrize("name", EMCO)
def test_emco_half_profile_reproduces_the_drawn_entities(name):
    drawn = drawn_end_points(name)
    below = all(y <= 1e-9 for _, y in drawn)
    expected = [(x, abs(y)) for x, y in drawn]  # drawn below the axis: mirrored onto it
    profile = read_drawing(DXF / name).profile
    vertices = [s.start for s in profile.segments] + [profile.end]
    for point in expected:
        assert min(math.dist(point, v) for v in vertices) <= 0.01, point
    assert profile.closed_by_axis and profile.mirrored == below
    z_values = [x for x, _ in drawn]
    assert profile.start[0] == pytest.approx(max(z_values)) and profile.end[0] == pytest.approx(min(z_values))
    closing = profile.closing_segments()
    assert closing[0].start == profile.end and closing[-1].end == profile.start
    assert closing[0].end[1] == 0.0 and closing[-1].start[1] == 0.0


@pytest.mark.parametrize("name", EMCO)
def test_emco_arc_directions_match_the_other_tools_program(name):
    words = nc_arc_words(name)
    assert len(words) == 4 and words[:2] == words[2:]  # the finish pass, then its subroutine copy
    arcs = [s for s in read_drawing(DXF / name).profile.segments if isinstance(s, Arc)]
    assert [arc.ccw for arc in arcs] == [word == "03" for word in words[:2]]


def scaled_point(x: float, y: float) -> tuple[float, float]:
    return (x * INCH, y * INCH)


def test_seed_convention_drawing_geometry_in_mm(tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    drawing = read_drawing(tmp_path / "part.dxf")
    assert (drawing.units, drawing.scale_to_mm) == ("in", pytest.approx(INCH))
    corners = [(0, 0), (0, 0.5), (-1, 0.5), (-2, 0.5), (-3, 0.5), (-4, 0.5), (-4, 0)]
    profile = drawing.profile
    assert [s.start for s in profile.segments] + [profile.end] == [
        pytest.approx(scaled_point(*c)) for c in corners]
    assert [type(s) for s in profile.segments] == [Line, Line, Arc, Arc, Line, Line]
    assert profile.closed_by_axis and not profile.mirrored
    sagitta = 0.5 * 1 / 2  # bulge · chord / 2
    assert profile.bounds == pytest.approx((-4 * INCH, 0, 0, (0.5 + sagitta) * INCH))
    assert drawing.tool_change == pytest.approx(scaled_point(1, 1.5))


def test_seed_convention_arc_directions_after_ocs(tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    bulged, extruded = [s for s in read_drawing(tmp_path / "part.dxf").profile.segments if isinstance(s, Arc)]
    # Positive bulge, followed in the order drawn: counter-clockwise (§E).
    assert bulged.ccw is True
    assert bulged.centre == pytest.approx(scaled_point(*bulge_center((-1, 0.5), (-2, 0.5), 0.5)))
    # Counter-clockwise in an OCS with extrusion −Z is clockwise seen from +Z (§E).
    assert extruded.ccw is False
    assert extruded.centre == pytest.approx(scaled_point(-2.5, 0.5))


def test_seed_convention_operations_and_codes(tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    operations = read_drawing(tmp_path / "part.dxf").operations
    assert [(op.layer, op.kind) for op in operations] == [("1", "ROUGH"), ("2", "SLOT"), ("3", "THREAD")]
    assert operations[0].codes == {"spindle_rpm": 1000, "feed": 300, "tool": 1, "coolant": True}
    assert operations[1].codes == {"spindle_rpm": 80, "feed": 20, "tool": 2, "coolant": False}
    assert operations[2].codes == {"spindle_rpm": 700, "tool": 3, "thread_pitch": 1.5,
                                   "depth_per_pass": 0.4, "infeed_angle": 30}
    rough = operations[0]
    assert len(rough.paths) == 3
    assert rough.paths[0][0].start == pytest.approx(scaled_point(0.1, 0.9))
    assert rough.paths[0][0].end == pytest.approx(scaled_point(-3.9, 0.9))


def test_spline_and_ellipse_are_lines_within_the_tolerance(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_ellipse((-20, 0), major_axis=(20, 0), ratio=0.5, start_param=0, end_param=math.pi / 2)
    spline = msp.add_spline([(-20, 10), (-25, 12), (-30, 9), (-35, 10)])
    msp.add_line((-35, 10), (-40, 10))
    msp.add_line((-40, 10), (-40, 0))
    doc.saveas(tmp_path / "curves.dxf")
    profile = read_drawing(tmp_path / "curves.dxf").profile
    assert profile.closed_by_axis
    on_ellipse = [s for s in profile.segments if s.start[0] >= -20 - 1e-9 and s.end[0] >= -20 - 1e-9]
    assert len(on_ellipse) > 10
    for s in on_ellipse:  # the true ellipse between two chord ends stays within tolerance
        t0, t1 = (math.atan2(p[1] / 10, (p[0] + 20) / 20) for p in (s.start, s.end))
        deviation = max(distance_to_chord(((-20 + 20 * math.cos(t), 10 * math.sin(t))), s)
                        for t in (t0 + (t1 - t0) * k / 50 for k in range(51)))
        assert deviation <= FLATTEN_TOLERANCE_MM * 1.01
    exact = [(v.x, v.y) for v in spline.construction_tool().approximate(400)]
    on_spline = [s for s in profile.segments
                 if -35 - 1e-9 <= min(s.start[0], s.end[0]) and max(s.start[0], s.end[0]) <= -20 + 1e-9]
    for point in exact:
        assert min(distance_to_segment(point, s) for s in on_spline) <= FLATTEN_TOLERANCE_MM * 1.01


def distance_to_chord(point, segment) -> float:
    (x0, y0), (x1, y1) = segment.start, segment.end
    return abs((x1 - x0) * (y0 - point[1]) - (x0 - point[0]) * (y1 - y0)) / math.dist(segment.start, segment.end)


def distance_to_segment(point, segment) -> float:
    (x0, y0), (x1, y1) = segment.start, segment.end
    dx, dy = x1 - x0, y1 - y0
    t = max(0.0, min(1.0, ((point[0] - x0) * dx + (point[1] - y0) * dy) / (dx * dx + dy * dy)))
    return math.dist(point, (x0 + t * dx, y0 + t * dy))


def test_no_profile_is_refused_naming_what_was_found(tmp_path):
    doc = ezdxf.new("R2010")
    doc.layers.add("1")
    doc.modelspace().add_line((0, 1), (-10, 1), dxfattribs={"layer": "1"})
    doc.saveas(tmp_path / "empty0.dxf")
    with pytest.raises(DxfError, match=r"layer 0 has no profile.*layer '1': 1 segment"):
        read_drawing(tmp_path / "empty0.dxf")


def test_bad_code_value_names_layer_handle_and_text(tmp_path):
    handles = seed_drawing(tmp_path / "bad.dxf", rough_codes="@GROUGH @Sfast @T01")
    with pytest.raises(DxfError) as caught:
        read_drawing(tmp_path / "bad.dxf")
    message = str(caught.value)
    assert "layer '1'" in message and f"handle {handles['rough']}" in message
    assert "'@GROUGH @Sfast @T01'" in message and "@S" in message


def test_operation_layer_without_type_is_refused(tmp_path):
    seed_drawing(tmp_path / "untyped.dxf", layer2_codes="@S80 @F20 @T02")
    with pytest.raises(DxfError, match=r"layer '2' .*no @G code"):
        read_drawing(tmp_path / "untyped.dxf")


def test_binary_dxf_is_read_like_the_same_drawing_in_ascii(tmp_path):
    seed_drawing(tmp_path / "part.dxf", fmt="bin")
    seed_drawing(tmp_path / "ascii.dxf")
    assert (tmp_path / "part.dxf").read_bytes().startswith(b"AutoCAD Binary DXF")
    binary, ascii_ = read_drawing(tmp_path / "part.dxf"), read_drawing(tmp_path / "ascii.dxf")
    assert binary.profile.segments == ascii_.profile.segments
    assert binary.operations == ascii_.operations and binary.tool_change == ascii_.tool_change


def test_the_real_binary_file_is_read_with_the_entities_ezdxf_reads():
    name = "ezdxf_binary_dxf_R2000.dxf"
    assert (DXF / name).read_bytes().startswith(b"AutoCAD Binary DXF")
    expected = [(e.dxftype(), e.dxf.handle) for e in ezdxf.readfile(DXF / name).modelspace()]
    loaded = load_drawing_file(DXF / name)
    assert [(e.dxftype(), e.dxf.handle) for e in loaded.doc.modelspace()] == expected == [("TEXT", expected[0][1])]


@pytest.mark.parametrize("keep", [0.5, 0.99])
def test_a_truncated_binary_dxf_is_refused_in_one_line(tmp_path, keep):
    whole = (DXF / "ezdxf_binary_dxf_R2000.dxf").read_bytes()
    (tmp_path / "cut.dxf").write_bytes(whole[: int(len(whole) * keep)])
    with pytest.raises(DxfError, match="truncated binary DXF") as caught:
        read_drawing(tmp_path / "cut.dxf")
    assert "\n" not in str(caught.value)


def test_truncated_file_is_refused(tmp_path):
    whole = (DXF / EMCO[1]).read_bytes()
    (tmp_path / "half.dxf").write_bytes(whole[: len(whole) // 2])
    with pytest.raises(DxfError, match="truncated DXF"):
        read_drawing(tmp_path / "half.dxf")


@pytest.mark.parametrize("content, reason", [
    (b"G0 X10 Z5\nM30\n", "not a DXF file"), (b"AC1032\x00\x00binary", "DWG file"), (b"", "not a DXF file")])
def test_other_files_are_refused(tmp_path, content, reason):
    (tmp_path / "thing.dxf").write_bytes(content)
    with pytest.raises(DxfError, match=reason):
        read_drawing(tmp_path / "thing.dxf")


def test_damaged_files_are_refused_or_read_never_crash(tmp_path):
    lines = (DXF / EMCO[2]).read_bytes().split(b"\n")
    rng = random.Random(5)
    for attempt in range(25):
        damaged = list(lines)
        for _ in range(2):
            where = rng.randrange(4, len(damaged) - 4)
            damaged[where:where + 1] = rng.choice([[b"abc"], [], [b"0", b"LINE"], [b"nan"]])
        (tmp_path / f"{attempt}.dxf").write_bytes(b"\n".join(damaged))
        try:
            read_drawing(tmp_path / f"{attempt}.dxf")
        except DxfError as refusal:
            assert "\n" not in str(refusal)


def test_open_chain_the_axis_cannot_close_is_refused_with_the_reason(tmp_path):
    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 5), (-10, 5), (-10, 8), (-2, 8)])  # ends inside its Z range
    doc.saveas(tmp_path / "hook.dxf")
    with pytest.raises(DxfError, match="not its smallest and largest Z"):
        read_drawing(tmp_path / "hook.dxf")


def test_second_point_on_layer_0_is_refused(tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    doc = ezdxf.readfile(tmp_path / "part.dxf")
    extra = doc.modelspace().add_point((2, 2))
    doc.saveas(tmp_path / "part.dxf")
    with pytest.raises(DxfError, match=f"2 POINTs .*{extra.dxf.handle}"):
        read_drawing(tmp_path / "part.dxf")


def test_chaining_joins_ends_within_tolerance_only():
    touching = [Line((0, 1), (-5, 1)), Line((-10, 1), (-5.005, 1)), Line((-10.05, 1), (-15, 1))]
    chains = chain_segments(touching)
    assert [len(c.segments) for c in chains] == [2, 1]
    assert chains[0].segments[1] == Line((-5.005, 1), (-10, 1))  # reversed to continue the first


def text(value: str) -> CodeText:
    return CodeText("4", "A1", value)


@pytest.mark.parametrize("written, parsed", [
    ("@GROUGH@S100", {"kind": "ROUGH", "spindle_rpm": 100}),
    ("@g finish @s = 1200 @F:0,15", {"kind": "FINISH", "spindle_rpm": 1200, "feed": 0.15}),
    ("see info@shop.example @T2", {"tool": 2}),
    ("@GPART\n@M08", {"kind": "PART", "coolant": True}),
])
def test_code_spellings(written, parsed):
    assert codes_in(text(written)) == parsed


@pytest.mark.parametrize("written, fragment", [
    ("@X5", "unknown code @X"), ("@M7", "8 (coolant on) or 9"), ("@A95", "angle"), ("@S-5", "greater than 0"),
    ("@Sinf", "must be a number"), ("@GMILL", "ROUGH | SLOT"), ("@T0", "tool number"), ("@G", "bad value ''"),
    ("@T²", "must be a tool number"), ("@T" + "1" * 5000, "must be a tool number"),
])
def test_bad_codes_are_refused(written, fragment):
    with pytest.raises(DxfError, match=re.escape(fragment)):
        codes_in(text(written))


def test_one_code_with_two_values_on_a_layer_is_refused():
    with pytest.raises(DxfError, match="given twice"):
        layer_codes([text("@GROUGH @S100"), CodeText("4", "A2", "@S200")])
