"""Numbers that name something are references, not quantities (issue 17): a plain parameter whose
value equals the contour number of LinuxCNC's G71.1, the 840D tool edge D1, the spindle of
SETMS(1) or a PlasmaC output channel leaves it as written and says what it names; where the
block makes the same address a quantity (G71's depth D, G70's count of passes P), it binds. What
each test expects is read off the real files by a regular expression of its own."""
from __future__ import annotations

import json
import re

import psycopg
import pytest
from helpers.nc_files import DATA, FAMILY, binds, instantiated, stored_at, stored_rows
from helpers.outcomes import one_line_error

from engine.library.nc_import import import_nc

DEMO = "linuxcnc/lathe_g70_71_demo.ngc"
CAM = "sinumerik/cam_840dsl/CAM_TEST.MPF"
PIERCE = FAMILY + "metric_ramp_pierce.ngc"


def lines_of(relative: str) -> list[str]:
    return (DATA / relative).read_text().splitlines()


def found(relative: str, block: str, word: str) -> list[tuple[int, str]]:
    """(line, word) of each `word` (a regex) in the lines matching `block`, comments removed."""
    hits = []
    for number, line in enumerate(lines_of(relative), start=1):
        code = re.sub(r"\([^()]*\)|;.*", "", line)
        if re.search(block, code, re.IGNORECASE):
            hits += [(number, match.group()) for match in re.finditer(word, code)]
    return hits


def left(report, parameter: str) -> list[tuple[int, str]]:
    return [(entry["line"], entry["word"]) for entry in report.left_alone if entry["parameter"] == parameter]


def test_the_contour_g70_and_g71_call_stays_and_the_report_says_what_it_names(conn):
    calls = found(DEMO, r"^\s*G7[01]", r"\bQ100\b")
    assert len(calls) == 3 and found(DEMO, r"^O100 SUB", r"O100")
    report = import_nc(conn, DATA / DEMO, "nc_contour", {"depth": 100, "feed": 400})
    assert left(report, "depth") == calls
    assert all(entry["why"] == "Q100 names the contour (its last block, or its subprogram)"
               for entry in report.left_alone if entry["parameter"] == "depth")
    assert report.bindings[0]["words"] == 0
    assert instantiated(conn, "nc_contour", {"depth": 250, "feed": 400}) == lines_of(DEMO)


def test_where_the_cycle_makes_d_a_depth_and_p_a_count_of_passes_they_bind(conn):
    """G71.1's D1 is the depth of cut and G70's P2 the passes (LinuxCNC), G42.1's L2 the
    cutter's orientation and T2 a tool: a depth of 1 and a count of 2 change just the first two."""
    original = lines_of(DEMO)
    depth_line, = {number for number, _ in found(DEMO, r"^G71\.1", r"\bD1\b")}
    pass_line, = {number for number, _ in found(DEMO, r"^G70\b", r"\bP2\b")}
    orientation_line, = {number for number, _ in found(DEMO, r"^G42\.1", r"\bL2\b")}
    tool_line, = {number for number, _ in found(DEMO, r"T2M6", "T2")}
    import_nc(conn, DATA / DEMO, "nc_cycles", {"depth": 1, "passes": 2, "feed": 400})
    produced = instantiated(conn, "nc_cycles", {"depth": 3, "passes": 5, "feed": 400})
    assert produced[depth_line - 1] == re.sub(r"\b([DI])1\b", r"\g<1>3", original[depth_line - 1])
    assert produced[pass_line - 1] == re.sub(r"\bP2\b", "P5", original[pass_line - 1])
    assert "L2" in produced[orientation_line - 1] and "T2M6" in produced[tool_line - 1]


def test_the_840d_tool_edge_and_master_spindle_are_left_alone_with_their_reason(conn):
    edges = found(CAM, r"\bD1\b", r"\bD1\b")
    spindle = [number for number, line in enumerate(lines_of(CAM), start=1) if "SETMS(1)" in line]
    assert len(edges) >= 3 and len(spindle) == 1
    report = import_nc(conn, DATA / CAM, "nc_edges", {"passes": 1})
    whys = {(entry["line"], entry["word"]): entry["why"] for entry in report.left_alone}
    assert all(whys[edge] == "D1 names the tool edge or offset register" for edge in edges)
    assert whys[(spindle[0], "1")] == "1 names the master spindle"
    rows = stored_rows(conn, "nc_edges")
    assert not any("{passes" in rows[number] for number, _ in edges + [(spindle[0], "")])


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_bound_form_naming_d_binds_the_edge_its_user_named(conn):
    edges = found(CAM, r"\bD1\b", r"\bD1\b")
    import_nc(conn, DATA / CAM, "nc_edge", {"edge": {"value": 1, "addresses": ["D"]}})
    produced = instantiated(conn, "nc_edge", {"edge": 2})
    assert [produced[number - 1] for number, _ in edges] == [
        re.sub(r"\bD1\b", "D2", lines_of(CAM)[number - 1]) for number, _ in edges]


def test_plasma_io_channels_stay_and_the_values_they_carry_bind(conn):
    """M65 P3 switches output 3 and M67/M68 E3 set analog channel 3: both left alone; q3 of
    m159 (a creep distance) and M67's Q100 (a velocity in percent) are quantities and bind."""
    channels = found(PIERCE, r"^\s*M6[5-8]", r"\b[EP]3\b")
    carried = found(PIERCE, r"^\s*m159|^\s*M67", r"\b[qQ](3|100)\b")
    assert channels and carried
    report = import_nc(conn, DATA / PIERCE, "nc_pierce", {"three": 3, "hundred": 100})
    assert sorted(left(report, "three")) == channels
    rows = stored_rows(conn, "nc_pierce")
    assert all(binds(rows[number], "three") or binds(rows[number], "hundred") for number, _ in carried)


# --- the command -------------------------------------------------------------------------------


def test_a_bound_form_naming_the_contour_address_is_refused_and_nothing_stored(read_only_run, tmp_path):
    first_call = found(DEMO, r"^\s*G7[01]", r"\bQ100\b")[0][0]
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"depth": {"value": 100, "addresses": ["Q"]}}))
    before = stored_at(read_only_run.url)
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_jump", "--params", params)
    assert one_line_error(result), result.output
    assert f"line {first_call}:" in result.stderr and "contour" in result.stderr and "depth" in result.stderr
    assert stored_at(read_only_run.url) == before


def test_the_warning_says_what_the_number_names(run, tmp_path):
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"depth": 100, "feed": 400}))
    result = run("import-nc", DATA / DEMO, "--class", "nc_warned", "--params", params)
    assert result.exit_code == 0, result.output
    warnings = [line for line in result.stderr.splitlines() if "left as written" in line]
    assert len(warnings) == len(found(DEMO, r"^\s*G7[01]", r"\bQ100\b"))
    assert all("Q100 equals depth, but Q100 names the contour" in warning for warning in warnings)


@pytest.mark.parametrize("given", ["name,value,addresses\nfeed,=400,F\n", "name,value,addresses\nfeed,nan,F\n",
                                   '{"feed": NaN}', '{"feed": {"value": Infinity, "addresses": ["F"]}}'])
def test_a_value_no_word_can_hold_is_refused_naming_the_parameter(read_only_run, tmp_path, given):
    params = tmp_path / ("p.json" if given.startswith("{") else "p.csv")
    params.write_text(given)
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_nan", "--params", params)
    assert one_line_error(result) and str(params) in result.stderr and "'feed'" in result.stderr, result.output


def test_a_plain_text_parameter_is_kept_for_the_template(run, tmp_path):
    params = tmp_path / "p.csv"
    params.write_text("name,value,addresses\nfeed,400,F\nprogram_name,PAWN,\n")
    result = run("import-nc", DATA / DEMO, "--class", "nc_text", "--params", params)
    assert result.exit_code == 0, result.output
    with psycopg.connect(run.url) as connection:
        kept = connection.execute("SELECT import_params FROM gear_class WHERE name = 'nc_text'").fetchone()[0]
    assert kept == {"feed": 400, "program_name": "PAWN"}


def test_a_name_given_twice_inside_a_bound_form_is_refused(read_only_run, tmp_path):
    params = tmp_path / "p.json"
    params.write_text('{"feed": {"value": 400, "value": 3.0, "addresses": ["F"]}}')
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_twice", "--params", params)
    assert one_line_error(result) and "'value' appears twice" in result.stderr, result.output


def test_a_plain_parameter_does_not_turn_the_contour_a_g71_calls_into_a_quantity(conn):
    """LinuxCNC's G71/G70 name the contour subroutine by Q (`G71.1 Q100` runs `O100 SUB`): Q100
    is a program number, like the O it names. A plain parameter whose value is 100 (a depth, a
    speed) binds those Q words, not the O100 label, so the class made with another value calls a
    subroutine the program does not have (or another contour)."""
    subs = {match for line in (DATA / DEMO).read_text().splitlines() for match in re.findall(r"^\s*O(\d+)\s+SUB", line)}
    assert subs == {"100"}
    import_nc(conn, DATA / DEMO, "nc_q", {"depth": 100, "feed": 400})
    lines = instantiated(conn, "nc_q", {"depth": 200, "feed": 400})
    called = {match for line in lines for match in re.findall(r"^\s*G7[01][.\d]*\s+Q(\d+)", line)}
    defined = {match for line in lines for match in re.findall(r"^\s*O(\d+)\s+SUB", line)}
    assert called and called <= defined, \
        f"the G70/G71 lines call O{sorted(called)}, the program defines O{sorted(defined)}"


def test_a_plain_parameter_does_not_rebind_the_tool_edge_or_the_spindle_number(conn):
    """On the 840D, D1 selects the tool's cutting edge (as T selects the tool) and SETMS(1) the
    master spindle: numbers that are codes. A plain parameter of value 1 (passes, a count) binds
    every D1 and the SETMS argument of Siemens' CAM_TEST.MPF, so the class made with passes=2
    cuts with edge D2's offsets on spindle 2."""
    original = (DATA / CAM).read_text().splitlines()
    edges = [line for line in original if re.search(r"\bD1\b", line)]
    assert edges and any("SETMS(1)" in line for line in original)
    import_nc(conn, DATA / CAM, "nc_d", {"passes": 1})
    lines = instantiated(conn, "nc_d", {"passes": 2})
    assert [line for line in lines if re.search(r"\bD1\b", line)] == edges
    assert any("SETMS(1)" in line for line in lines)
