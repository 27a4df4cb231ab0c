"""Real Fanuc/Haas lathe programs read by the ISO expander (issue 27), and the cycle geometry it
expands G70–G76 with (engine/verifier/expanders/cycles.py).

* Every real ISO lathe file under tests/data/nc/fanuc is either verified on the seeded
  `lathe-iso` record or refused naming the construct that stops it (asserted per file).
* The cycles make the moves the reference describes (docs/reference/iso-lathe.md): the expected
  numbers are computed here from the reference formulas (G71: ceil((start X − finish X)/(2·Δd))
  passes, retract e at 45°; G76: depth Δd·√n, at least Δdmin deeper each pass, flank infeed
  depth·tan(a/2)), not copied from the code.
* The attack forms of the issue, inserted after a real program's opening blocks, are refused
  naming their reason."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from helpers.iso_real_programs import FANUC_0T, REAL, cut, plain_moves, verdict
from helpers.verifier_programs import LATHE_ISO, accepted, refusal
from msgspec.structs import replace

import engine.verifier.expansion as expansion
from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program
from engine.verifier.expanders import cycles
from engine.verifier.expanders.cycles import FEED, RAPID, THREAD, Move, Thread
from engine.verifier.expanders.iso import expand_iso
from engine.verifier.expansion import ExpansionRefused

DATA = Path(__file__).resolve().parent / "data" / "nc" / "fanuc"



def real_lines(name: str) -> list[str]:
    return (DATA / name).read_text(encoding="ascii").splitlines()


def test_every_real_iso_lathe_file_is_in_the_table():
    assert sorted(path.name for path in DATA.iterdir()) == sorted(REAL)


@pytest.mark.parametrize("name", sorted(REAL))
def test_a_real_iso_lathe_program_is_verified_or_refused_naming_the_construct(conn, name):
    machine, verified, construct = REAL[name]
    message = verdict(conn, machine, real_lines(name))
    if verified:
        assert message is None, message
    else:
        assert message is not None and construct in message, message


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_tokarka_with_its_plane_stated_is_refused_for_its_commented_out_tool_calls(conn):
    lines = real_lines("TOKARKA.NC")
    message = verdict(conn, "lathe-iso", lines[:1] + ["G18"] + lines[1:])
    assert message is not None and "line 13" in message and "no tool offset active" in message, message


# ---------------------------------------------------------------- decimal point input, headers

def test_x118_is_118_mm_under_calculator_input_and_refused_under_increment_input(conn):
    calculator = load_machine(conn, FANUC_0T)
    assert calculator.decimal_point_input == "calculator"
    moves = plain_moves(calculator, cut(["G01 X118 Z-45 F0.3"]))
    assert moves == [pytest.approx((118.0, -45.0))]        # X118 = X118. mm, not 0.118 mm
    increment = replace(calculator, decimal_point_input="increment")
    with pytest.raises(ExpansionRefused, match="X118 needs a decimal point"):
        expand_iso(cut(["G01 X118 Z-45 F0.3"]), increment)


@pytest.mark.parametrize("header", ["%O1200(TOKARKA)", "%O1200 (TOKARKA)"])
def test_the_tape_mark_and_the_program_number_on_one_first_line_are_accepted(conn, header):
    assert verdict(conn, FANUC_0T, [header] + cut(["G01 X118. F0.3"])[2:]) is None


def test_a_tape_mark_and_program_number_after_the_first_line_is_refused(conn):
    message = verdict(conn, FANUC_0T, cut(["%O1201", "G01 X118. F0.3"]))
    assert message is not None and "%O1201" in message, message


# ---------------------------------------------------------------- custom macro B

MACRO_PASSES = [
    "#1=120.", "#2=2.5", "#3=#2*4+#2*[3-1]*2+80.",      # 10 + 10 + 80 = 100 mm, the finished diameter
    "WHILE [#1 GT #3] DO 1",
    "#1=#1-#2*2",                                      # 2·depth on the diameter
    "IF [#1 LT #3] THEN #1=#3",
    "G01 X#1 Z-[#3/4] F0.25",                          # each pass to Z−25
    "G00 U2. Z2.",
    "END 1",
    "#4=ROUND[2.5]",                                   # 3: ROUND in an assignment rounds to a whole number
    "IF [#3 EQ 100] GOTO 100",
    "G00 X9999.",                                      # skipped by the GOTO: past the X travel
    "N100 G00 X[SQRT[#3*#3]+50.] Z[#4+0.5]",           # X150 Z3.5
]


def test_macro_b_loops_and_jumps_evaluate_to_plain_passes(conn):
    finish, depth = 10 + 10 + 80.0, 2.5
    levels, diameter = [], 120.0
    while diameter > finish:
        diameter = max(diameter - 2 * depth, finish)
        levels.append(diameter)
    moves = plain_moves(load_machine(conn, FANUC_0T), cut(MACRO_PASSES))
    assert moves == [pytest.approx((x, -finish / 4)) for x in levels]
    assert verdict(conn, FANUC_0T, cut(MACRO_PASSES)) is None


def test_a_value_from_an_expression_is_rounded_as_the_control_rounds_it(conn):
    """A dimension to the least input increment, 0.001 mm; an S value to a whole r/min, a half
    away from zero (Fanuc: S[1000.5] is S1001)."""
    body = ["#1=2.", "G97 S[#1*400.25] M03", "G01 X[100./3.] Z-10. F0.2"]
    texts = [line.text for line in expand_iso(cut(body), load_machine(conn, FANUC_0T))]
    speed = math.floor(2 * 400.25 + 0.5)
    assert any(f"S{speed}" in text.split() for text in texts), texts
    moves = plain_moves(load_machine(conn, FANUC_0T), cut(body))
    assert moves == [pytest.approx((round(100 / 3, 3), -10.0), abs=1e-9)]


@pytest.mark.parametrize("body, reason", [
    (["G00 X#5021"], "#5021 is a system variable: it holds positions and work offsets"),
    (["#1=#2001"], "#2001 is a system variable: it holds tool compensation values"),
    (["#3000=1"], "#3000 is a system variable: setting it changes the alarm"),
    (["G00 X[#7+1.]"], "#7 is read before this program sets it: it is vacant"),
    (["G00 X#510"], "#510 is read before this program sets it: it is a value an earlier program left"),
    (["#1=ATAN[1]/[1]"], "ATAN: its result depends on parameter 6004#0"),
    (["#1=0", "#2=5/#1"], "5/0: a division by zero"),
    (["GOTO 77"], "GOTO 77: there is no block N77"),
    (["WHILE [1 EQ 2] DO 2", "G00 X100."], "DO 2 without its END 2"),
    (["G65 P9100 A1."], "G65 calls a macro program"),
    (["#1=3.5", "G#1 X100."], "G3.5: a G code from an expression must be whole"),
    (["G00 X#0"], "#0 is always vacant"),
])
def test_a_macro_construct_that_cannot_be_followed_is_refused_naming_it(conn, body, reason):
    message = verdict(conn, FANUC_0T, cut(body))
    assert message is not None and reason in message, message


def test_a_macro_loop_that_never_ends_is_refused_at_the_step_bound(conn, monkeypatch):
    """The bound is engine.verifier.expansion.MAX_STEPS (a million lines; lowered here so the test
    runs in a moment): the loop's WHILE line is the one named."""
    # 6 blocks before the loop, then WHILE, #1=…, END: the 5,005th block is a WHILE (7 + 3·4,999)
    monkeypatch.setattr(expansion, "MAX_STEPS", 5_004)
    body = ["#1=0", "WHILE [#1 GE 0] DO 1", "#1=#1+1", "END 1"]
    message = verdict(conn, FANUC_0T, cut(body))
    assert message is not None and "more than 5,004 blocks" in message, message
    assert "line 9 'WHILE [#1 GE 0] DO 1'" in message, message


# ---------------------------------------------------------------- attacks in a real program

def opening() -> list[str]:
    """FANUC0T.nc's first operation up to its approach (lines 4–9: spindle clamp G50 S600, tool
    T0202, gear range, G96 S450 M03, rapid to X86. Z0.25) under the engine's own header lines
    (the file itself relies on the control's power-on G21/G99, which the grammar wants stated)."""
    return LATHE_ISO + ["G99"] + [line.strip() for line in real_lines("FANUC0T.nc")[3:9]]


def with_body(body: list[str], start: list[str] | None = None) -> list[str]:
    return (start or opening()) + body + ["G00 X200. Z150.", "M30", "%"]


def test_the_real_opening_with_a_plain_cut_is_verified(conn):
    accepted(conn, "lathe-iso", with_body(["G01 X80. F0.3", "Z-20.", "G00 X90."]))


@pytest.mark.parametrize("body, reason", [
    (["G00 X9999."], "X"),                                 # a rapid past the X travel (0 … 400)
    (["G01 Z-700. F0.3"], "Z"),                            # a feed past the Z travel (−600 … 200)
    (["G97 S9000"], "S9000"),                              # over spindle_max 4000 r/min
    (["G01 X80. F0.3", "Z-20.", "T0303"], "changes the tool at"),   # the turret indexes at the cut
    (["M98 P1234"], "not in this file"),                   # a subprogram the file does not hold
    (["M99"], "starts it again for ever"),                 # M99 in the main program: an endless loop
])
def test_an_attack_inserted_into_a_real_program_is_refused_with_its_reason(conn, body, reason):
    message = refusal(conn, "lathe-iso", with_body(body))
    assert reason in message, message


@pytest.mark.parametrize("speed", ["G96 S0", "G97 S0"])
def test_a_cut_after_a_spindle_speed_of_0_is_refused(conn, speed):
    """The real opening turns at G96 S450 under the clamp G50 S600; S0 stops the spindle (a surface
    speed of 0 is 0 r/min at any X), so the cut after it would meet a standing bar."""
    message = refusal(conn, "lathe-iso", with_body([speed, "G01 X80. F0.3"]))
    assert "S0" in message and "above 0" in message, message


def test_g96_without_the_clamp_of_the_real_program_is_refused(conn):
    start = [line for line in opening() if "G50" not in line]
    message = refusal(conn, "lathe-iso", with_body(["G01 X80. F0.3"], start))
    assert "G96 constant surface speed without a spindle clamp" in message, message


# ---------------------------------------------------------------- cycle geometry

def cut_passes(moves: list[Move], start_z: float) -> list[tuple[float, float]]:
    """(level X, end Z) of each roughing pass: a feed along Z from the start Z at one diameter."""
    return [(move.x, move.z) for before, move in zip(moves, moves[1:])
            if move.motion == FEED and before.z == start_z and before.x == move.x and move.z != start_z]


def test_g71_roughs_in_passes_of_twice_the_depth_on_the_diameter_down_to_the_allowance():
    start, depth, retract, (u, w) = (60.0, 2.0), 2.0, 0.5, (0.4, 0.1)
    contour = [Move(RAPID, 20.0, 2.0), Move(FEED, 20.0, -30.0), Move(FEED, 60.0, -30.0)]
    moves = cycles.rough(start, contour, depth, retract, (u, w))
    finish_x = 20.0 + u
    count = math.ceil((start[0] - finish_x) / (2 * depth))
    levels = [start[0] - 2 * depth * n for n in range(1, count)] + [finish_x]
    *passes, contour_pass = cut_passes(moves, start[1])     # the last one follows the offset contour
    assert contour_pass == pytest.approx((finish_x, -30.0 + w))
    assert [x for x, _ in passes] == pytest.approx(levels)
    assert all(z == pytest.approx(-30.0 + w) for _, z in passes)     # each pass ends at the shoulder + W
    # after each pass the tool lifts by e (radius) at 45°: +2e on the diameter, +e along Z
    ends = [i for i, m in enumerate(moves) if m.motion == FEED and (m.x, m.z) in passes]
    lifts = [(moves[i + 1].x - moves[i].x, moves[i + 1].z - moves[i].z) for i in ends[:count]]
    assert lifts == [pytest.approx((2 * retract, retract))] * count
    # then one pass along the contour offset by U/W, and back to the start at rapid
    assert moves[-3:] == [Move(FEED, 20.0 + u, -30.0 + w), Move(FEED, 60.0 + u, -30.0 + w), Move(RAPID, *start)]


def test_g72_faces_in_passes_of_the_depth_along_z():
    start, depth = (62.0, 2.0), 1.5
    contour = [Move(RAPID, 62.0, -10.0), Move(FEED, 30.0, -10.0), Move(FEED, 30.0, 0.0)]
    moves = cycles.rough(start, contour, depth, 0.5, (0.0, 0.0), facing=True)
    count = math.ceil((start[1] - -10.0) / depth)
    levels = [start[1] - depth * n for n in range(1, count)] + [-10.0]
    cuts = [m.z for before, m in zip(moves, moves[1:])
            if m.motion == FEED and before.x == start[0] and before.z == m.z and m.x != start[0]]
    assert cuts[:-1] == pytest.approx(levels)      # then the pass along the contour at its Z
    assert cuts[-1] == pytest.approx(-10.0)


def test_g70_follows_the_contour_and_returns_to_the_start():
    contour = [Move(RAPID, 20.0, 2.0), Move(FEED, 20.0, -30.0), Move(FEED, 60.0, -30.0)]
    assert cycles.finish((62.0, 2.0), contour) == [*contour, Move(RAPID, 62.0, 2.0)]


def reference_depths(first: float, height: float, minimum: float, allowance: float, finish: int) -> list[float]:
    """Fanuc G76: pass n cuts to Δd·√n, at least Δdmin deeper than the pass before, while above
    k − d; then k − d, then the finish passes at k."""
    depths: list[float] = []
    n = 1
    while True:
        depth = max(first * math.sqrt(n), (depths[-1] + minimum) if depths else 0.0)
        if depth >= height - allowance:
            return depths + [height - allowance] + [height] * finish
        depths.append(depth)
        n += 1


def test_g76_cuts_each_pass_deeper_by_the_square_root_rule_along_the_flank():
    # M20 × 2.5: root X17.4 (20 − 2·1.3), k 1.3, Δd 0.4, Δdmin 0.1, d 0.05, one finish pass, 60°
    thread = Thread(17.4, -20.0, 1.3, 0.4, 2.5, minimum=0.1, allowance=0.05, finish_passes=1, angle=60.0)
    start = (22.0, 3.0)
    depths = reference_depths(0.4, 1.3, 0.1, 0.05, 1)
    moves = cycles.threading(start, thread)
    cuts = [(before, move) for before, move in zip(moves, moves[1:]) if move.motion == THREAD]
    assert len(cuts) == len(depths)
    for (before, thread_pass), depth in zip(cuts, depths):
        assert thread_pass.x == pytest.approx(17.4 + 2 * (1.3 - depth))      # the diameter at that depth
        assert thread_pass.z == pytest.approx(-20.0)
        # the infeed follows the flank: the start Z moves back by depth · tan(30°)
        assert before.z == pytest.approx(start[1] + depth * math.tan(math.radians(30.0)))
    assert all(b - a > 0 or b == a for a, b in zip(depths, depths[1:]))


def test_g76_with_no_height_is_refused():
    with pytest.raises(cycles.CycleError):
        cycles.threading((22.0, 3.0), Thread(17.4, -20.0, 0.0, 0.4, 2.5))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_program_whose_header_names_another_program_is_refused_saying_what_to_give(conn):
    """A new user imported TOKARKA.NC as class y2 and made it as _Y2: its header %O1200(TOKARKA)
    would store it on the control as TOKARKA; the refusal names both and the param that settles it."""
    with pytest.raises(LimitError) as raised:
        verify_program(real_lines("TOKARKA.NC"), load_machine(conn, "lathe-iso"), "_Y2")
    message = str(raised.value)
    assert "names program TOKARKA, but this program is _Y2" in message
    assert "give program_name TOKARKA in the job's params" in message
