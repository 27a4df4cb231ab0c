"""The Fanuc hobbing forms besides the gear box (issue 30; reference fanuc-egb.md §F8): the
tailstock M20/M21 and the door M codes as on the 840D hobber, the dwell `G04 X<s>` (seconds,
with its point) or `G04 P<ms>` (a whole number), the path modes G61 (exact stop mode) and G64
(cutting mode) for the 840D's G60/G64, coolant M8/M9 and a tool call T outside synchronisation.
The verifier reads them in a hand-written program and refuses each malformed one in one line;
the simulation proves the seeded templates' programs rewritten in these forms
(tests/helpers/fanuc_programs.py) as it proves the 840D programs: the same findings, the same
cycle time, the tailstock held clamped for every cut."""
from __future__ import annotations

import math

import pytest
from helpers.fanuc_cases import twin
from helpers.fanuc_programs import fanuc_program
from helpers.verifier_programs import verifier_refusal, with_line_replaced
from msgspec.structs import replace

from engine.hobbing.choices import Choices
from engine.machines.records import Machine, load_machine
from engine.simulation import simulate_program
from engine.simulation.hobbing.report import SimulationError
from engine.verifier import verify_program

NAME = "GEAR42"
DOORS = {"door_close_m": 60, "door_open_m": 61}
PROGRAM = ["%", f"O1234 ({NAME})", "(GEAR 42 SPUR)", "G21 G90 G94 G54", "T1", "M60 (DOOR CLOSE)",
           "M20 (TAILSTOCK CLAMP)", "G0 X61.000 Y0.000", "G0 Z19.576 A1.763", "G81 T19 L-1", "M3 S246", "M8",
           "G0 X52.500", "G1 X51.500 F13.3", "G64 (CUTTING MODE)", "G1 Z-23.380 F29.7", "G61 (EXACT STOP MODE)",
           "G04 X2.5", "G04 P1500", "G0 X61.000", "M9", "G80", "M5", "G0 Z100.000", "M21 (TAILSTOCK RELEASE)",
           "M61 (DOOR OPEN)", "M30", "%"]
TAPER, CROWNED, WORM_WHEEL = 50, 51, 53       # seeded gears of the classes that write G60/G64 or G4


@pytest.fixture
def fanuc(conn) -> Machine:
    """The seeded hobber's record in the Fanuc dialect, with door M codes M60/M61."""
    return replace(load_machine(conn, "hobber-840d"), name="hobber-fanuc", dialect="fanuc", **DOORS)


def replaced(old: str, *new: str, lines: list[str] = PROGRAM) -> list[str]:
    return with_line_replaced(lines, old, *new)


def refusal(machine: Machine, lines: list[str]) -> str:
    return verifier_refusal(machine, lines, NAME)


def test_the_fanuc_forms_of_tailstock_doors_dwell_and_path_mode_are_read(fanuc):
    verify_program(PROGRAM, fanuc, NAME)
    verify_program([line.replace("G04 X2.5", "G4 X2.5") for line in PROGRAM], fanuc, NAME)


@pytest.mark.parametrize("old, new, reason", [
    ("G04 X2.5", "G04", "G04 without its X or P: a dwell states its time"),
    ("G04 X2.5", "G04 X25", "X25 needs a decimal point"),            # 0.025 s under IS-B, not 25 s
    ("G04 X2.5", "G04 X-1.", "X-1. must be above 0"),
    ("G04 X2.5", "G04 X0.", "X0. must be above 0"),
    ("G04 X2.5", "G04 X100000.", "a dwell of 100000 s, above the 99999.999 s"),
    ("G04 P1500", "G04 P1.5", "P is a whole number of milliseconds"),
    ("G04 P1500", "G04 P-1500", "P is a whole number of milliseconds"),
    ("G04 P1500", "G04 P0", "P0 must be above 0"),
    ("G04 P1500", "G04 X1.5 P1500", "G04 with X1.5 and P1500: a dwell states its time once"),
    ("G04 X2.5", "G04 X2.5 M9", "a G04 block (dwell) holds only X, P, not M9"),
    ("G04 X2.5", "G04 Z2.5", "a G04 block (dwell) holds only X, P, not Z2.5"),
    ("G04 X2.5", "G04 F2.5", "a G04 block (dwell) holds only X, P, not F2.5"),    # the 840D's form
    ("G04 X2.5", "G04 X=2.5", "a G04 block (dwell) holds only X, P, not X=2.5"),
    ("G04 X2.5", "G0 G04 X2.5", "a G04 block (dwell) holds only X, P, not G0"),
    ("G61 (EXACT STOP MODE)", "G60 (EXACT STOP)", "G60 is single-direction positioning on a Fanuc control"),
    ("G61 (EXACT STOP MODE)", "G61 G64", "G61 and G64 in one block are both path mode"),
    ("G61 (EXACT STOP MODE)", "G09", "G9 is not a G code of the Fanuc hobbing"),
    ("G64 (CUTTING MODE)", "G63", "G63 is not a G code of the Fanuc hobbing"),
    ("M20 (TAILSTOCK CLAMP)", "M20 M21", "M20 and M21 in one block are both tailstock"),
    ("M60 (DOOR CLOSE)", "M60 M61", "M60 and M61 in one block are both door"),
])
def test_each_malformed_form_is_refused_by_its_block(fanuc, old, new, reason):
    lines = replaced(old, new)
    message = refusal(fanuc, lines)
    assert f"line {lines.index(new) + 1} {new!r}" in message and reason in message


def test_door_m_codes_are_the_records_own(fanuc):
    """The door M functions are the machine builder's: a record that names none reads no M60."""
    message = refusal(replace(fanuc, door_close_m=None, door_open_m=None), PROGRAM)
    assert "line 6 'M60 (DOOR CLOSE)': M60 is not an M code of the Fanuc hobbing in G54 grammar" in message


def test_a_tool_call_and_coolant_are_read_outside_synchronisation(fanuc):
    """T<n> before G81 (and after G80 with the hob stopped) and M8/M9 anywhere: as on main;
    T while synchronised is refused (tests/test_fanuc_hobbing_grammar.py)."""
    verify_program(replaced("G0 Z100.000", "G0 Z100.000", "T2", "M8", "M9"), fanuc, NAME)
    assert "a tool call T while the table is synchronised" in refusal(fanuc, replaced("G04 X2.5", "T2"))


# ---------------------------------------------------------------- the simulation


@pytest.fixture
def case(conn, monkeypatch):
    return lambda gear_id, choices=Choices(), **senses: twin(conn, monkeypatch, gear_id, choices, **senses)


def proved_alike(lines, gear, hob, siemens, fanuc, **mistake):
    """The Fanuc form of `lines`, after checking that it and the 840D program have no findings
    that refuse and the same cycle time (min) and table speed (r/min)."""
    translated = fanuc_program(lines, gear, hob, fanuc, **mistake)
    expected, report = simulate_program(lines, gear, hob, siemens), simulate_program(translated, gear, hob, fanuc)
    assert expected.refusals == [] and report.refusals == [], report.lines()
    assert math.isclose(report.cycle_time, expected.cycle_time) and report.teeth == expected.teeth
    assert math.isclose(report.table_speed, expected.table_speed)
    return translated


def test_the_tailstock_clamped_by_m20_is_proved_and_a_release_before_the_cut_refused(case):
    lines, gear, hob, siemens, fanuc = case(42)
    translated = proved_alike(lines, gear, hob, siemens, fanuc)
    assert "M20 (TAILSTOCK CLAMP)" in translated and "M21 (TAILSTOCK RELEASE)" in translated
    infeed = next(number for number, line in enumerate(translated) if line.startswith("G1 X"))
    released = [*translated[:infeed], "M21", *translated[infeed:]]
    found = [finding for finding in simulate_program(released, gear, hob, fanuc).refusals
             if f"tailstock released by M21 at line {infeed + 1}" in finding.message]
    assert found and found[0].line == translated[infeed]
    in_cut = [*translated[:infeed], f"{translated[infeed]} M21", *translated[infeed + 1:]]
    assert any("tailstock released by M21" in finding.message
               for finding in simulate_program(in_cut, gear, hob, fanuc).refusals)


def test_the_door_m_codes_are_proved_as_the_840ds(case, conn):
    conn.execute("UPDATE machine SET door_close_m = 60, door_open_m = 61 WHERE name = 'hobber-840d'")
    lines, gear, hob, siemens, fanuc = case(42)
    translated = proved_alike(lines, gear, hob, siemens, fanuc)
    assert "M60 (DOOR CLOSE)" in translated and "M61 (DOOR OPEN)" in translated


@pytest.mark.parametrize("gear_id", [TAPER, CROWNED])
def test_taper_and_crowned_programs_run_their_cuts_in_g64_and_stop_exactly_in_g61(case, gear_id):
    """The 840D's `G64 ; CONTINUOUS PATH` … `G60 ; EXACT STOP` around each cut's X(Z) path are
    Fanuc's G64 (cutting mode) … G61 (exact stop mode): modal path modes that move no axis, so the
    moves, the time and the proof are the 840D program's. Left as G60 the Fanuc program is refused."""
    lines, gear, hob, siemens, fanuc = case(gear_id)
    assert "G64 ; CONTINUOUS PATH" in lines and "G60 ; EXACT STOP" in lines
    translated = proved_alike(lines, gear, hob, siemens, fanuc)
    assert translated.count("G64 (CONTINUOUS PATH)") == lines.count("G64 ; CONTINUOUS PATH")
    assert translated.count("G61 (EXACT STOP)") == lines.count("G60 ; EXACT STOP")
    left = [line.replace("G61 ", "G60 ") for line in translated]
    with pytest.raises(SimulationError, match="G60 is single-direction positioning on a Fanuc control"):
        simulate_program(left, gear, hob, fanuc)


def test_a_worm_wheels_dwell_at_depth_counts_its_seconds_written_either_way(case):
    """The 840D's `G4 F<s>` is `G04 X<s>`; `G04 P<ms>` dwells the same; each adds its seconds/60
    to the cycle time (a program without it is that much shorter)."""
    lines, gear, hob, siemens, fanuc = case(WORM_WHEEL)
    translated = proved_alike(lines, gear, hob, siemens, fanuc, helix="")    # radial: no Z term (§F6)
    dwell = next(line for line in translated if line.startswith("G04 X"))
    seconds = float(dwell.removeprefix("G04 X"))
    assert f"G4 F{seconds:.1f}" in lines and seconds > 0
    with_p = [f"G04 P{round(seconds * 1000)}" if line == dwell else line for line in translated]
    without = [line for line in translated if line != dwell]
    timed = {name: simulate_program(program, gear, hob, fanuc).cycle_time
             for name, program in (("X", translated), ("P", with_p), ("none", without))}
    assert math.isclose(timed["P"], timed["X"])
    assert math.isclose(timed["X"] - timed["none"], translated.count(dwell) * seconds / 60)
