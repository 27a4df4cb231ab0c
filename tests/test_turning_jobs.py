"""Turning jobs from DXF drawings (design notes §8), at library level on the seeded database
(each test rolled back): the programs of both dialects, the profile-only jobs, alternating
work steps, edits in SQL, the lathe check, and the templates stored once.

Expected values come from the drawings (seed_drawing's numbers, the Emco files through
ezdxf, the NC programs another tool made of them) and from geometry, not from the engine."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from helpers.drawings import DXF, EMCO, INCH, nc_arc_words, seed_drawing
from helpers.drawn_parts import profile_only_drawing, two_rough_layers
from helpers.lathe_programs import distance_to_drawn, drawn_polylines, motions, operation_lines, words
from psycopg.types.json import Jsonb

from engine.errors import EngineError
from engine.library.refactor import refactor
from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions
from engine.turning.names import MAX_OPERATIONS
from engine.verifier import LimitError
from importers.dxf import import_dxf

# ISO F words carry their decimal point (a Fanuc-type control reads F300 by a parameter's unit).
DIALECTS = {"lathe-iso": {"tools": ("T0101", "T0202"), "thread": "G32", "coolant": ("M08", "M09"),
                          "feeds": ("F300.000", "F20.000"), "pitch": "F1.5000"},
            "lathe-840d": {"tools": ("T1 D1", "T2 D2"), "thread": "G33", "coolant": ("M8", "M9"),
                           "feeds": ("F300", "F20"), "pitch": "K1.5"}}


def program_of(conn, path, machine="lathe-iso", **options) -> list[str]:
    alternate = options.pop("alternate", None)
    program_name = options.pop("program_name", None)
    report = import_dxf(conn, path, machine, ProfileOptions(**options), alternate, program_name)
    return instantiate_job(conn, report.job_id).lines


@pytest.fixture
def seed_part(tmp_path) -> Path:
    seed_drawing(tmp_path / "part.dxf")
    return tmp_path / "part.dxf"


@pytest.mark.parametrize("machine", DIALECTS)
def test_seed_drawing_program_carries_every_code_of_the_drawing(conn, seed_part, machine):
    lines = program_of(conn, seed_part, machine)
    dialect = DIALECTS[machine]
    text = "\n".join(lines)
    for word in ("S1000", "S80", "S700", *dialect["feeds"]):
        assert word in words_of(lines), word
    assert all(tool in lines for tool in dialect["tools"])
    rough = operation_lines(lines, 1)
    on, off = dialect["coolant"]
    assert rough.index(on) < rough.index(off) and text.count(on) == 1 and text.count(off) == 1
    assert off not in operation_lines(lines, 2)          # @M9 on the slot layer: no coolant
    depth = (0.5 - 0.45) * INCH                            # crest and root lines of layer 3
    passes = [line for line in operation_lines(lines, 3) if line.startswith(dialect["thread"] + " ")]
    assert len(passes) == math.ceil(depth / 0.4)
    assert all(dialect["pitch"] in line.split() for line in passes)


def words_of(lines: list[str]) -> set[str]:
    return {word for line in lines for word in line.split()}


@pytest.mark.parametrize("machine, head, tail", [
    ("lathe-iso", ["%", "O"], ["M05", "M30", "%"]),
    ("lathe-840d", ["%_N_PART_MPF", ";$PATH=/_N_MPF_DIR"], ["M5", "M30"])])
def test_program_layout_per_dialect(conn, seed_part, machine, head, tail):
    lines = program_of(conn, seed_part, machine)
    assert lines[0] == head[0] and lines[1].startswith(head[1])
    assert lines[-len(tail):] == tail
    tool_change = lines[-len(tail) - 1]
    assert words(tool_change) == pytest.approx({"G": 0, "X": 2 * 1.5 * INCH, "Z": 1 * INCH}, abs=1e-3)
    assert any("part.dxf" in line for line in lines[:6]) and any(machine in line for line in lines[:6])


@pytest.mark.parametrize("name", EMCO)
def test_emco_finish_pass_follows_the_drawn_profile(conn, name):
    lines = program_of(conn, DXF / name, rough_depth=1.0, program_name="EMCO_PART")   # the file names are too long
    finish = operation_lines(lines, 2)
    cuts = [(g, start, end) for g, start, end in motions(finish) if g in (1, 2, 3)]
    drawn = drawn_polylines(DXF / name)
    for _, _, end in cuts:
        assert distance_to_drawn(end, drawn) <= 0.01, end
    vertices = {point for line in drawn for point in (line[0], line[-1])}
    reached = [end for _, _, end in cuts]
    for vertex in vertices:   # every drawn end point is a point of the finish pass
        assert min(math.dist(vertex, point) for point in reached) <= 0.01, vertex
    arc_words = [f"0{g}" for g, _, _ in cuts if g in (2, 3)]
    assert arc_words == nc_arc_words(name)[:2]


def test_profile_only_rough_passes_keep_the_allowance(conn, tmp_path):
    profile_only_drawing(tmp_path / "shaft.dxf")
    allowance = 0.5
    lines = program_of(conn, tmp_path / "shaft.dxf", rough_depth=1.5, allowance=allowance)
    drawn = drawn_polylines(tmp_path / "shaft.dxf")
    feeds = [(start, end) for g, start, end in motions(operation_lines(lines, 1)) if g == 1]
    assert len(feeds) > 10
    for start, end in feeds:
        for k in range(21):
            point = (start[0] + (end[0] - start[0]) * k / 20, start[1] + (end[1] - start[1]) * k / 20)
            # the program states positions to 0.001 mm: that much rounding is allowed
            assert distance_to_drawn(point, drawn) >= allowance - 0.001, point
    stock_radius = math.ceil(2 * 15 + 2) / 2           # default blank: largest diameter + 2 mm
    assert max(end[1] for _, end in feeds) <= stock_radius


def test_alternate_machines_two_rough_operations_pass_by_pass(conn, tmp_path):
    two_rough_layers(tmp_path / "wheel.dxf")
    lines = program_of(conn, tmp_path / "wheel.dxf", alternate=[1, 2])
    cut_radii = [start[1] for g, start, end in motions(operation_lines(lines, 1))
                 if g == 1 and start[1] == end[1]]
    assert cut_radii == [20, 25, 18, 23, 16]            # a1 b1 a2 b2 a3 (each layer outermost first)
    assert operation_lines(lines, 2) == []
    plain = program_of(conn, tmp_path / "wheel.dxf")
    assert [start[1] for g, start, end in motions(operation_lines(plain, 1)) if g == 1 and start[1] == end[1]] \
        == [20, 18, 16]


def test_alternating_needs_one_tool(conn, tmp_path):
    two_rough_layers(tmp_path / "wheel.dxf", tool_two="02")
    with pytest.raises(EngineError, match=r"prep:2.tool = 2 differs from prep:1.tool = 1"):
        import_dxf(conn, tmp_path / "wheel.dxf", alternate=[1, 2])


def test_an_edited_segment_is_refused_the_part_is_the_drawings(conn, tmp_path):
    """Issue 26: the part is the drawing record's; a profile edited in SQL is named, nothing stored."""
    profile_only_drawing(tmp_path / "shaft.dxf")
    report = import_dxf(conn, tmp_path / "shaft.dxf", options=ProfileOptions(rough_depth=1.0))
    # The shoulder at radius 8 (segment 1 of the profile, from Z 0 to Z −10) becomes radius 9.
    params = conn.execute("SELECT params FROM job WHERE id = %s", (report.job_id,)).fetchone()[0]
    assert params["profile"][1][:5] == ["line", 0, 8, -10, 8]
    params["profile"][0][4] = params["profile"][1][2] = params["profile"][1][4] = params["profile"][2][2] = 9
    conn.execute("UPDATE job SET params = %s WHERE id = %s", (Jsonb(params), report.job_id))
    with pytest.raises(EngineError, match=rf"job {report.job_id}: params\.profile\[0\] = \['line', 0\.0, 0\.0, "
                                          r"0\.0, 9\] is not .*8\.0\].*import-dxf"):
        instantiate_job(conn, report.job_id)
    assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == 0


def test_program_beyond_the_lathe_is_not_stored(conn, seed_part):
    report = import_dxf(conn, seed_part, materials=(None, "aluminium"))
    count = conn.execute("SELECT count(*) FROM program").fetchone()[0]
    # S5000 is beyond lathe-iso's 4000 r/min yet inside the cutting-data table (reference §E1) only
    # for a thread in aluminium: π·25.4·5000/1000 = 399 m/min, within carbide's 40-480 (Iscar)
    conn.execute("UPDATE job SET module_params = jsonb_set(module_params, '{cutcond:3,spindle_rpm}', '5000') "
                 "WHERE id = %s", (report.job_id,))
    with pytest.raises(LimitError, match=r"line \d+ 'G97 S5000 M03': spindle speed S5000 exceeds lathe-iso"):
        instantiate_job(conn, report.job_id)
    # the tool-change position is the drawing record's (issue 26): an edit is named, not run
    conn.execute("UPDATE job SET params = jsonb_set(params, '{tool_change_x}', '900') WHERE id = %s",
                 (report.job_id,))
    with pytest.raises(EngineError, match=r"params\.tool_change_x = 900 is not"):
        instantiate_job(conn, report.job_id)
    assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == count


def test_an_operation_switched_off_in_sql_leaves_the_program(conn, seed_part):
    report = import_dxf(conn, seed_part)
    conn.execute("UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:2,op_present}', 'false') "
                 "WHERE id = %s", (report.job_id,))
    lines = instantiate_job(conn, report.job_id).lines
    assert operation_lines(lines, 2) == [] and "T0202" not in lines and "G97 S80 M03" not in lines
    assert operation_lines(lines, 1) and operation_lines(lines, 3)


def test_a_bad_edit_is_named(conn, seed_part):
    report = import_dxf(conn, seed_part)
    conn.execute("UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:3,depth_per_pass}', '0') "
                 "WHERE id = %s", (report.job_id,))
    with pytest.raises(EngineError, match=r"cutmotion:3\.depth_per_pass = 0 must be a number above 0"):
        instantiate_job(conn, report.job_id)


@pytest.mark.parametrize("segment, words", [
    ('"line"', r"params\.profile\[1\] = 'line' is not a segment"),
    ('["line", 0, 8, -10]', r"params\.profile\[1\] = \['line', 0, 8, -10\]: a line is \[\"line\", z0"),
    ('["line", 0, "8", -10, 8]', r"a line is"),
    ('["arc", 0, 8, -10, 8, -2, 8, true]', r"not on one circle about the centre"),
])
def test_a_broken_segment_edited_in_sql_is_named_and_nothing_stored(conn, tmp_path, segment, words):
    profile_only_drawing(tmp_path / "shaft.dxf")
    report = import_dxf(conn, tmp_path / "shaft.dxf", options=ProfileOptions(rough_depth=1.0))
    count = conn.execute("SELECT count(*) FROM program").fetchone()[0]
    conn.execute("UPDATE job SET params = jsonb_set(params, '{profile,1}', %s::jsonb) WHERE id = %s",
                 (segment, report.job_id))
    with pytest.raises(EngineError, match=words):
        instantiate_job(conn, report.job_id)
    assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == count


def test_operation_slots_are_stored_once_and_refactor_changes_nothing(conn):
    for gear_class in ("turning_iso", "turning_840d"):
        slot_rows, bodies = conn.execute(
            "SELECT count(*), count(DISTINCT component_id) FROM assembly WHERE gear_class = %s "
            "AND id BETWEEN 1000 AND %s", (gear_class, 1000 * MAX_OPERATIONS + 999)).fetchone()
        assert slot_rows == 8 * MAX_OPERATIONS and bodies == 8
    assert conn.execute("SELECT parent FROM gear_class WHERE name IN ('turning_iso', 'turning_840d')").fetchall() \
        == [("turning",), ("turning",)]
    assert refactor(conn).changed is False


def test_the_machine_dialect_picks_the_class(conn, seed_part):
    iso = import_dxf(conn, seed_part, "lathe-iso")
    sinumerik = import_dxf(conn, seed_part, "lathe-840d")
    classes = dict(conn.execute("SELECT id, gear_class FROM job WHERE id IN (%s, %s)", (iso.job_id, sinumerik.job_id)))
    assert classes == {iso.job_id: "turning_iso", sinumerik.job_id: "turning_840d"}
    assert conn.execute("SELECT gear_id FROM job WHERE id = %s", (iso.job_id,)).fetchone() == (None,)
