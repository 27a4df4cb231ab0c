"""A turning job's parameters edited in SQL, its program and its CLI flags: every bad value is
refused in one line naming the parameter, before the template runs, and nothing is stored
(design notes §8–9). Jobs come from the seed drawing (inch, three operations) and a
two-layer drawing; each test rolled back."""
from __future__ import annotations

import pytest
from helpers.drawings import seed_drawing
from helpers.drawn_parts import two_rough_layers
from helpers.turning_jobs import refused_after
from msgspec.structs import replace

from engine.errors import EngineError
from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program
from importers.dxf import import_dxf

MODULE = "module_params = jsonb_set(module_params, '{%s}', '%s')"
DROP = "module_params = module_params #- '{%s}'"
JOB = "params = jsonb_set(params, '{%s}', '%s')"


@pytest.mark.parametrize("set_sql, message", [
    (DROP % "cutmotion:1,feed", r"module_params\.cutmotion:1\.feed = None must be a number above 0"),
    (MODULE % ("cutmotion:1,feed", '"fast"'), r"cutmotion:1\.feed = 'fast' must be a number above 0"),
    (MODULE % ("cutmotion:1,feed", "0"), r"cutmotion:1\.feed = 0 must be a number above 0"),
    ("module_params = module_params - 'cutcond:1'", r"module_params\.cutcond:1 is missing"),
    ("module_params = module_params - 'prep:1'", r"module_params\.prep:1 is missing"),
    (MODULE % ("cutcond:1,spindle_rpm", "null"), r"cutcond:1\.spindle_rpm = None must be a number above 0"),
    (MODULE % ("prep:1,tool", "123"), r"prep:1\.tool = 123 must be a whole number 1 … 99"),
    (MODULE % ("prep:1,tool", "1.5"), r"prep:1\.tool = 1\.5 must be a whole number"),
    (MODULE % ("prep:1,tool_offset", '"a"'), r"prep:1\.tool_offset = 'a' must be a whole number 1 … 99"),
    # T0100: no offset
    (MODULE % ("prep:1,tool_offset", "0"), r"prep:1\.tool_offset = 0 must be a whole number 1 … 99"),
    (MODULE % ("cutmotion:2,op_present", '"false"'), r"cutmotion:2\.op_present = 'false' must be true or false"),
    (MODULE % ("cutcond:2,coolant", '"no"'), r"cutcond:2\.coolant = 'no' must be true or false"),
    (MODULE % ("cutmotion:1,kind", '"rough"'), r"cutmotion:1\.kind = 'rough' is not one of"),
    (DROP % "cutmotion:3,thread_pitch", r"cutmotion:3\.thread_pitch = None must be a number above 0"),
    (MODULE % ("cutmotion:3,infeed_angle", "89"), r"cutmotion:3\.infeed_angle = 89 must be 0 … 60 degrees"),
    (JOB % ("clearance", '"2"'), r"params\.clearance = '2' must be a number above 0"),
    (JOB % ("tool_change_x", "null"), r"params\.tool_change_x = None must be a number"),
    (JOB % ("stock_diameter", "-5"), r"params\.stock_diameter = -5 must be a number above 0"),
    (JOB % ("closed_by_axis", '"false"'), r"params\.closed_by_axis = 'false' must be true or false"),
    (JOB % ("program_number", "123456"), r"params\.program_number = 123456 must be a whole number 1 … 8999"),
    (JOB % ("program_number", "9000"), r"params\.program_number = 9000 must be a whole number 1 … 8999"),   # macros
])
def test_a_bad_or_missing_parameter_is_refused_by_name(conn, seed_job, set_sql, message):
    refused_after(conn, seed_job, set_sql, message)


def test_alternated_operations_must_share_the_spindle_speed(conn, tmp_path):
    two_rough_layers(tmp_path / "wheel.dxf")
    job_id = import_dxf(conn, tmp_path / "wheel.dxf", alternate=[1, 2]).job_id
    refused_after(conn, job_id, MODULE % ("cutcond:2,spindle_rpm", "700"),
                  r"module_params\.cutcond:2\.spindle_rpm = 700 differs from cutcond:1\.spindle_rpm = 500")


def test_alternate_with_a_different_speed_is_refused_at_import(conn, tmp_path):
    two_rough_layers(tmp_path / "wheel.dxf")
    text = (tmp_path / "wheel.dxf").read_text().replace("@GROUGH @S500 @F200 @T01", "@GROUGH @S600 @F200 @T01", 1)
    (tmp_path / "wheel.dxf").write_text(text)
    jobs = conn.execute("SELECT count(*) FROM job").fetchone()[0]
    with pytest.raises(EngineError, match=r"cutcond:2\.spindle_rpm = 500(\.0)? differs from cutcond:1\.spindle_rpm"):
        import_dxf(conn, tmp_path / "wheel.dxf", alternate=[1, 2])
    assert conn.execute("SELECT count(*) FROM job").fetchone()[0] == jobs


def test_a_broken_profile_chain_is_refused_by_index(conn, seed_job):
    refused_after(conn, seed_job, "params = jsonb_set(params, '{profile,1,1}', "
                                  "to_jsonb((params #>> '{profile,1,1}')::numeric + 1))",
                  r"params\.profile\[1\] starts at .* must meet within 0\.01 mm")


ISO_START = ["%", "O0001 (PART)", "G21 G18 G40 G90", "T0101", "G97 S500 M03", "G98 F150."]
ISO_END = ["M30", "%"]


@pytest.mark.parametrize("lines, message", [
    (["G00 X10.000 Z5.000", "G03 X10.000 Z-5.000 R5.000"], r"the arc reaches X20 exceeds the travel"),
    (["G98 F1e-05"], r"F1e-05: an exponent"),
    (["G97 S0 M03"], r"S0 must be above 0"),
    (["T12301"], r"T12301 is not T<tool><offset>"),
])
def test_the_lathe_check_refuses(conn, lines, message):
    machine = load_machine(conn, "lathe-iso")
    narrow = replace(machine, x_max=15.0)
    with pytest.raises(LimitError, match=message):
        verify_program(ISO_START + lines + ISO_END, narrow, "PART")


def test_a_lathe_arc_within_the_travel_passes(conn):
    machine = load_machine(conn, "lathe-iso")
    verify_program(ISO_START + ["G00 X10.000 Z5.000", "G02 X10.000 Z-5.000 R5.000"] + ISO_END, machine, "PART")


def test_an_inch_drawing_says_its_codes_are_not_scaled(conn, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    notes = import_dxf(conn, tmp_path / "part.dxf").notes
    assert any("scaled ×25.4" in note and "@F in mm/min" in note for note in notes), notes


@pytest.mark.parametrize("value", ["0", "abc", "nan", "inf"])
def test_a_bad_option_value_is_one_line_and_exit_1(read_only_run, tmp_path, value):
    seed_drawing(tmp_path / "part.dxf")
    result = read_only_run("import-dxf", tmp_path / "part.dxf", "--rough-depth", value)
    assert result.exit_code == 1, result.output
    assert result.stderr.strip().splitlines() == [result.stderr.strip()]
    assert "--rough-depth" in result.stderr and value in result.stderr


def test_a_missing_option_is_one_line_and_exit_1(read_only_run):
    result = read_only_run("instantiate", "--job", "abc")
    assert result.exit_code == 1 and len(result.stderr.strip().splitlines()) == 1, result.output
