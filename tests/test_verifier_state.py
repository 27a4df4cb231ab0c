"""The verifier after the attack of issue 13's review: numbers of any size are refused, never a
crash; no cut without the machine state it needs (spindle, coupling, tool offset, units and
modes stated) and nothing after M30; ISO dimension words with their decimal point and no % in
a comment; the header naming the program itself; a thread's lead × S, the table's speed with
its differential terms, and an arc's radius against its chord; and, end to end, a template row
or a stored job that makes one of these stores nothing, with one line and exit 1.

Expected values come from the reference formulas, computed here: the table turns at
n_C = (z0/z2)·n_B + k_Z·v_Z/360 (§A5, k in degrees of C per mm, v in mm/min); a thread's tool
travels lead × S mm/min along Z; no circle of radius R passes through two points farther apart
than 2R."""
from __future__ import annotations

import math

import psycopg
import pytest
from helpers.verifier_programs import HOBBING, LATHE_ISO, READY, accepted, one_line_exit_1, program, programs, refusal

from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program

MAX_FEED = 20000.0           # mm/min: the verifier's feed bound (about a rapid traverse)
MAX_DIFFERENTIAL = 360.0     # °/mm: one table turn per mm of travel, a lead of 1 mm
HUGE = "1" + "0" * 400       # a float overflows at 309 digits
PYTHON_INT_LIMIT = "1" + "0" * 4400   # int() refuses more than 4300 digits
EGDEF = "EGDEF(C,B,1)"
EGON = 'EGON(C,"FINE",B,-1,19)'
CUT = "G1 Z10.000 F100.0"


def hobbing(body: list[str]) -> list[str]:
    """A hobbing program of `body`, with Y positioned first (EGON needs it, reference §A7)."""
    return program("hobber-840d", ["G0 Y0.000", *body], ready=False)


# ---------------------------------------------------------------- 1. numbers of any size

@pytest.mark.parametrize("machine, line, reason", [
    ("hobber-840d", f'EGON(C,"FINE",B,{HUGE},19)', "401 digits"),
    ("hobber-840d", f'EGON(C,"FINE",B,-1,{HUGE})', "401 digits"),
    ("hobber-840d", f'EGON(C,"FINE",B,-1,{PYTHON_INT_LIMIT})', "4401 digits"),
    ("hobber-840d", f'EGON(C,"FINE",B,-1,19,Z,{HUGE},1)', "401 digits"),
    ("hobber-840d", f'EGON(C,"FINE",B,-1,19,Z,1,0.{"0" * 5000}1)', "5002 digits"),
    ("hobber-840d", "G0 X" + "1" * 5000, "5000 digits"),
    ("hobber-840d", "G0 X0." + "0" * 400 + "1", "402 digits"),
    ("hobber-840d", "G0 X" + "9" * 400 + ".5", "401 digits"),
    ("hobber-840d", "M3 S" + "9" * 4400, "4400 digits"),
    ("hobber-840d", "G" + "1" * 5000 + " X55", "5000 digits"),
    ("hobber-840d", "R11=R11+" + "1" * 500, "500 digits"),
    ("lathe-iso", "T" + "1" * 5000, "5000 digits"),
    ("lathe-840d", "G2 X10 Z5 CR=" + "1" * 400, "400 digits"),
])
def test_a_number_of_any_size_is_refused_never_a_crash(conn, machine, line, reason):
    message = refusal(conn, machine, program(machine, [line]))
    assert reason in message and len(message) < 500


def test_twelve_digits_are_read_and_thirteen_refused(conn):
    assert "13 digits" in refusal(conn, "hobber-840d", program("hobber-840d", ["G0 X55.00000000000"]))
    assert accepted(conn, "hobber-840d", program("hobber-840d", ["G0 X55.0000000000"]))


def test_a_template_row_emitting_a_huge_hob_ratio_stores_nothing(run, tmp_path):
    with psycopg.connect(run.url) as conn:   # row 1500 of spur: the EGON of the coupling
        conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 1500",
                     (repr(f'EGON(C,"FINE",B,-1,{HUGE})'),))
    before = programs(run.url)
    message = one_line_exit_1(run("instantiate", "--gear", 42, "--draft"))   # the editor tries it (a draft: no file)
    assert "401 digits" in message and "nothing stored" in message
    assert programs(run.url) == before and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("digits", [4400, 400])
def test_a_job_parameter_of_thousands_of_digits_is_refused_in_one_line(run, tmp_path, digits):
    made = run("instantiate", "--gear", 42, "--json")
    assert made.exit_code == 0, made.output
    with psycopg.connect(run.url) as conn:
        job = conn.execute("SELECT max(id) FROM job").fetchone()[0]
        conn.execute("UPDATE job SET params = jsonb_set(params, '{z2}', ('1' || repeat('0', %s))::jsonb) "
                     "WHERE id = %s", (digits, job))
    before = programs(run.url)
    for args in (("--job", job), ("--jobs", f"{job}-{job}")):
        message = one_line_exit_1(run("instantiate", *args, "--out", tmp_path))
        assert f"{digits + 1} digits" in message and "correct it in SQL" in message
        assert programs(run.url) == before and list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- 2. the machine state before a cut

@pytest.mark.parametrize("body, reason", [
    ([EGDEF, EGON, CUT], "a cut before any spindle speed S"),
    ([EGDEF, EGON, "M3", CUT], "a cut before any spindle speed S"),
    ([EGDEF, EGON, "M3 S246", "M5", CUT], "a cut with the spindle stopped"),
    (["M3 S246", CUT], "the table not coupled to the hob"),
    ([EGDEF, "M3 S246", CUT], "the table not coupled to the hob"),
    ([EGDEF, EGON, "M3 S246", "EGOFS(C)", CUT], "the table not coupled to the hob"),
    ([EGDEF, EGON, "M3 S246", "EGOFS(C)", "EGDEL(C)", CUT], "the table not coupled to the hob"),
    ([EGDEF, EGDEF], "EGDEL(C) first"),
    ([EGDEF, EGON, "EGOFS(C)", EGDEF], "EGDEL(C) first"),
    ([EGDEF, EGON, "EGDEL(C)"], "EGOFS(C) first"),
    ([EGON], "EGON before EGDEF"),
    (["M3 M5 S246"], "M3 and M5 in one block are both spindle"),
])
def test_a_hob_cut_needs_the_spindle_turning_and_the_table_coupled(conn, body, reason):
    assert reason in refusal(conn, "hobber-840d", hobbing(body))


def test_a_coupling_defined_again_after_egdel_and_one_switched_on_again_are_accepted(conn):
    assert accepted(conn, "hobber-840d", hobbing([EGDEF, EGON, "M3 S246", CUT, "EGOFS(C)", EGON, CUT, "M5",
                                                  "EGOFS(C)", "EGDEL(C)", EGDEF, EGON, "M3 S246", CUT]))


@pytest.mark.parametrize("code", ["G90", "G71", "G94"])
def test_a_hob_cut_needs_units_positions_and_feed_mode_stated(conn, code):
    lines = program("hobber-840d", ["G0 X55.000", CUT])
    lines[3] = " ".join(word for word in lines[3].split() if word != code)
    assert f"motion before {code} (" in refusal(conn, "hobber-840d", lines)


@pytest.mark.parametrize("machine, modes, move, reason", [
    ("lathe-iso", "G18 G40 G90", "G00 X20. Z0.", "motion before G21 (mm)"),
    ("lathe-iso", "G21 G18 G40", "G00 X20. Z0.", "motion before G90 (absolute positions)"),
    ("lathe-840d", "G18 G90 G40 DIAMON", "G0 X20 Z0", "motion before G71 (mm)"),
    ("lathe-840d", "G18 G71 G40 DIAMON", "G0 X20 Z0", "motion before G90 (absolute positions)"),
])
def test_even_a_rapid_needs_its_units_and_absolute_positions_stated(conn, machine, modes, move, reason):
    lines = program(machine, [move], ready=False)
    lines[3] = modes
    assert f"line 5 {move!r}: {reason}" in refusal(conn, machine, lines)


@pytest.mark.parametrize("machine, body, reason", [
    ("lathe-iso", ["T0303", "G97", "G00 X24.600 Z2.922", "G32 X24.600 Z-22.860 F1.5"],
     "a cut before any spindle speed"),
    ("lathe-iso", ["T0303", "G97 S700", "G00 X24.600 Z2.922", "G32 X24.600 Z-22.860 F1.5"],
     "a cut with the spindle stopped"),
    ("lathe-840d", ["T3 D3", "G97", "G0 X24.6 Z2.9", "G33 Z-22.86 K1.5"], "a cut before any spindle speed"),
    ("lathe-iso", ["T0303", "G00 X24.600 Z2.922", "G32 X24.600 Z-22.860 F1.5"], "motion before G97"),
    ("lathe-iso", ["T0101", "G97 S500 M03", "G00 X20. Z2.", "G01 X20. Z-10."], "motion before G98"),
    ("lathe-840d", ["T1 D1", "G97 S500 M3", "G0 X20 Z2", "G1 X20 Z-10"], "motion before G94"),
])
def test_a_lathe_cut_needs_the_spindle_turning_and_its_feed_mode(conn, machine, body, reason):
    assert reason in refusal(conn, machine, program(machine, body, ready=False))


@pytest.mark.parametrize("machine, body", [
    ("lathe-iso", ["T0303", "G97 S700 M03", "G00 X24.600 Z2.922", "G32 X24.600 Z-22.860 F1.5"]),
    ("lathe-840d", ["T3 D3", "G97 S700 M3", "G0 X24.6 Z2.9", "G33 Z-22.86 K1.5"]),
])
def test_a_thread_needs_no_feed_mode_its_lead_is_per_revolution(conn, machine, body):
    assert accepted(conn, machine, program(machine, body, ready=False))


@pytest.mark.parametrize("machine, lines, reason", [
    ("hobber-840d", HOBBING + READY["hobber-840d"] + [CUT], "does not end with M30"),
    ("hobber-840d", program("hobber-840d", []) + ["G0 X55.000"], "a line after M30"),
    ("hobber-840d", program("hobber-840d", []) + ["; a comment"], "a line after M30"),
    ("lathe-840d", program("lathe-840d", []) + ["M5"], "a line after M30"),
    ("lathe-iso", program("lathe-iso", [])[:-1], "the last line must be the tape mark %"),
    ("lathe-iso", program("lathe-iso", [])[:-1] + ["M05", "%"], "a line after M30"),
    ("hobber-840d", HOBBING[1:] + ["M30"], "the first line must be the program header"),
    ("lathe-iso", [LATHE_ISO[0]] + LATHE_ISO[2:] + ["M30", "%"], "the second line must be the program number"),
])
def test_a_program_ends_with_m30_and_nothing_follows(conn, machine, lines, reason):
    assert reason in refusal(conn, machine, lines)


def test_a_spur_program_without_its_egon_and_m3_rows_stores_nothing(run, tmp_path):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET p_emit = 'False' WHERE gear_class = 'spur' AND id IN (1500, 1700)")
    before = programs(run.url)
    message = one_line_exit_1(run("instantiate", "--gear", 42, "--draft"))   # the editor tries it (a draft: no file)
    # gear 42's radial infeed: the paper's 36 mm/min scaled with its axial feed, 8.11 → 3.0 mm/rev (§C, §D)
    radial = round(36.0 * 3.0 / (105.0 / (246 / 19)), 1)
    assert f"G1 X51.500 F{radial}" in message and "spindle" in message
    assert programs(run.url) == before and list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- 3. a tool offset before a cut

@pytest.mark.parametrize("machine, tool", [("lathe-iso", ["T0100"]), ("lathe-840d", ["T1 D0"]),
                                           ("lathe-840d", ["T1"]), ("lathe-840d", ["T1 D1", "T2"]),
                                           ("lathe-iso", ["T0101", "T0200"]), ("lathe-840d", ["T1 D1", "D0"])])
def test_a_cut_with_no_tool_offset_active_is_refused(conn, machine, tool):
    cut = "G01 X20. Z-10." if machine == "lathe-iso" else "G1 X20 Z-10"
    body = tool + READY[machine][1:] + [cut]
    assert "no tool offset active" in refusal(conn, machine, program(machine, body, ready=False))


@pytest.mark.parametrize("machine, tool", [("lathe-iso", ["T0102"]), ("lathe-840d", ["D1 T1"]),
                                           ("lathe-840d", ["T2", "D2"])])
def test_a_cut_with_its_tool_offset_is_accepted(conn, machine, tool):
    cut = "G01 X20. Z-10." if machine == "lathe-iso" else "G1 X20 Z-10"
    assert accepted(conn, machine, program(machine, tool + READY[machine][1:] + [cut], ready=False))


# ---------------------------------------------------------------- 4. ISO decimal points and %

@pytest.mark.parametrize("block, word", [
    ("G00 X114 Z2.", "X114"), ("G00 X114. Z2", "Z2"), ("G01 X20.000 Z-10", "Z-10"),
    ("G98 F150", "F150"), ("G32 X20. Z-10. F2", "F2"), ("G02 X20. Z-10. R5", "R5"),
])
def test_an_iso_dimension_word_without_its_decimal_point_is_refused(conn, block, word):
    lines = program("lathe-iso", ["G00 X20. Z0.", block])
    assert f"{word} needs a decimal point" in refusal(conn, "lathe-iso", lines)


def test_an_840d_word_without_a_point_is_millimetres_and_accepted(conn):
    assert accepted(conn, "lathe-840d", program("lathe-840d", ["G0 X114 Z2", "G1 X114 Z-10"]))


@pytest.mark.parametrize("where, line", [(2, "(DRAWING part%.dxf)"), (1, "O0001 (TE%ST)"),
                                         (4, "G00 X20. Z0. (NOTE 5%)")])
def test_a_percent_sign_in_an_iso_comment_is_refused(conn, where, line):
    lines = program("lathe-iso", ["G00 X20. Z0."])
    lines[where] = line
    refusal(conn, "lathe-iso", lines)


# ---------------------------------------------------------------- 5. the header names the program

@pytest.mark.parametrize("machine, header, name, reason", [
    ("hobber-840d", "%_N_GEAR43_MPF", "GEAR42", "the header names program GEAR43, but this program is GEAR42"),
    ("hobber-840d", "%_N_gear42_MPF", "GEAR42", "the header names program gear42"),
    ("hobber-840d", f"%_N_{'A' * 25}_MPF", "A" * 25, "at most 24 characters"),
    ("hobber-840d", "%_N_9GEAR_MPF", "9GEAR", "starting with two letters"),
    ("lathe-iso", "O0001 (GEAR43)", "GEAR42", "the header names program GEAR43, but this program is GEAR42"),
    ("lathe-iso", "O9000 (GEAR42)", "GEAR42", "program number O9000 is outside O0001 … O8999"),
    ("lathe-iso", "O0000 (GEAR42)", "GEAR42", "program number O0000 is outside"),
])
def test_the_header_must_name_this_program_with_a_safe_name(conn, machine, header, name, reason):
    lines = program(machine, [])
    lines[0 if machine == "hobber-840d" else 1] = header
    with pytest.raises(LimitError, match=reason.replace("(", r"\(")):
        verify_program(lines, load_machine(conn, machine), name)


def test_the_highest_iso_program_number_below_the_macros_is_accepted(conn):
    lines = program("lathe-iso", [])
    lines[1] = "O8999 (TEST)"
    assert accepted(conn, "lathe-iso", lines)


def test_a_template_row_naming_another_program_stores_nothing(run, tmp_path):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 100",
                     (repr("%_N_GEAR43_MPF"),))
    before = programs(run.url)
    message = one_line_exit_1(run("instantiate", "--gear", 42, "--draft"))   # the editor tries it (a draft: no file)
    assert "GEAR42 line 1 '%_N_GEAR43_MPF'" in message
    assert programs(run.url) == before and list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- 6. a thread's lead × S

@pytest.mark.parametrize("machine, speed, thread", [
    ("lathe-iso", 4000, "G32 X24.600 Z-22.860 F{lead}"), ("lathe-840d", 4000, "G33 Z-22.860 K{lead}")])
def test_a_thread_whose_lead_times_speed_exceeds_the_feed_bound_is_refused(conn, machine, speed, thread):
    tool, start = ("T0303", "G97 S{} M03") if machine == "lathe-iso" else ("T3 D3", "G97 S{} M3")
    fastest = MAX_FEED / speed                     # lead at which Z travels MAX_FEED mm/min
    def lines(lead: float) -> list[str]:
        return program(machine, [tool, start.format(speed), "G00 X24.600 Z2.922", thread.format(lead=lead)],
                       ready=False)
    assert accepted(conn, machine, lines(f"{fastest:.3f}"))
    assert f"feeds {60 * speed:g} mm/min along Z" in refusal(conn, machine, lines("60.000"))
    assert "along Z" in refusal(conn, machine, lines(f"{fastest + 0.001:.3f}"))


# ---------------------------------------------------------------- 7. the table with its differential

def table_speed(speed: float, starts: int, teeth: int, factor: float, feed: float) -> float:
    """Reference §A5: n_C = (z0/z2)·n_B + k·v/360, k in °/mm, v in mm/min."""
    return speed * starts / teeth + factor * feed / 360.0


def coupled_z(factor: str, *cut: str) -> list[str]:
    return hobbing(["EGDEF(C,B,1,Z,1)", f'EGON(C,"FINE",B,-1,19,Z,{factor},1)', "M3 S246", *cut])


def test_the_attack_s_differential_factor_is_refused(conn):
    lines = hobbing(["EGDEF(C,B,1,Z,1)", 'EGON(C,"FINE",B,1,19,Z,99999999999999,0.000000001)', "M3 S200",
                     "G1 Z10 F1000"])
    refusal(conn, "hobber-840d", lines)


def test_the_table_speed_adds_the_z_term_at_the_feed_of_the_cut(conn):
    table_max = load_machine(conn, "hobber-840d").table_speed_max
    at_1000 = (table_max - 246 / 19) * 360 / 1000          # k at which C reaches its maximum at F1000
    below, above = math.floor(at_1000 * 10) / 10, math.ceil(at_1000 * 10) / 10
    assert table_speed(246, 1, 19, below, 1000) <= table_max < table_speed(246, 1, 19, above, 1000)
    assert accepted(conn, "hobber-840d", coupled_z(f"{below:.1f}", "G1 Z10.000 F1000.0"))
    message = refusal(conn, "hobber-840d", coupled_z(f"{above:.1f}", "G1 Z10.000 F1000.0"))
    assert f"the table turns at {table_speed(246, 1, 19, above, 1000):.1f} r/min" in message


def test_the_z_term_counts_only_where_z_moves_and_at_rapid_for_g0(conn):
    """A G0 Z moves at the machine record's rapid rate (issue 14: rapid Z while coupled)."""
    machine = load_machine(conn, "hobber-840d")
    table_max, rapid = machine.table_speed_max, float(machine.rapid_rate)
    factor = math.ceil((table_max - 246 / 19) * 360 / rapid * 10 + 1) / 10   # C past its maximum at rapid
    assert table_speed(246, 1, 19, factor, 100) <= table_max < table_speed(246, 1, 19, factor, rapid)
    assert accepted(conn, "hobber-840d", coupled_z(f"{factor}", "G0 X55.000", "G1 Z10.000 F100.0"))
    assert "above hobber-840d's" in refusal(conn, "hobber-840d", coupled_z(f"{factor}", "G0 Z10.000"))


def test_a_differential_factor_above_a_turn_per_mm_is_refused(conn):
    assert "above 360°/mm" in refusal(conn, "hobber-840d", coupled_z(f"{MAX_DIFFERENTIAL + 1:g}"))
    assert accepted(conn, "hobber-840d", coupled_z(f"{MAX_DIFFERENTIAL:g}"))


# ---------------------------------------------------------------- 8. arcs that no circle makes

@pytest.mark.parametrize("machine, arc", [("lathe-iso", "G02 X398.000 Z-100.000 R0.100"),
                                          ("lathe-840d", "G2 X398.000 Z-100.000 CR=0.100")])
def test_an_arc_whose_radius_is_shorter_than_half_its_chord_is_refused(conn, machine, arc):
    start = "G00 X398.000 Z0.000" if machine == "lathe-iso" else "G0 X398.000 Z0.000"
    message = refusal(conn, machine, program(machine, [start, arc]))
    assert "the arc's radius 0.1 is shorter than half its chord (50.000)" in message


@pytest.mark.parametrize("radius, fits", [(10.0, True), (9.999, True), (9.997, False), (-10.0, True)])
def test_a_half_circle_fits_within_the_rounding_of_its_numbers(conn, radius, fits):
    half_chord = math.hypot((100.0 - 100.0) / 2, -20.0 - 0.0) / 2          # Z0 → Z−20 at X100 (a diameter)
    lines = program("lathe-iso", ["G00 X100.000 Z0.000", f"G02 X100.000 Z-20.000 R{radius:.3f}"])
    assert (abs(radius) + 0.002 >= half_chord) == fits
    if fits:
        assert accepted(conn, "lathe-iso", lines)
    else:
        assert "shorter than half its chord" in refusal(conn, "lathe-iso", lines)
