"""The LinuxCNC expander (engine.verifier.expanders.linuxcnc, issue 27) line by line: what each
construct makes, with the expected numbers worked out here from LinuxCNC's rules
(docs/reference/linuxcnc-lathe.md), and what it refuses."""
from __future__ import annotations

import math

import pytest
from helpers.linuxcnc_moves import START, moves
from helpers.linuxcnc_programs import LATHE, refusal

from engine.verifier.expanders.linuxcnc import expand_linuxcnc
from engine.verifier.expansion import ExpansionRefused

INCH = 25.4
def value(word: str, line: str) -> float:
    return float(next(token[len(word):] for token in line.split() if token.startswith(word)))


def parameter(expression: str) -> float:
    """The value of an expression, read back from the X it moves to (G8: X is the radius, so ×2)."""
    (line,) = moves("G8", f"#1 = {expression}", "G0 X#1")
    return value("X", line) / 2


@pytest.mark.parametrize("expression, expected", [
    ("[1 + 2 * 3]", 1 + 2 * 3), ("[2 ** 3 ** 2]", (2 ** 3) ** 2), ("[10 - 4 - 3]", 10 - 4 - 3),
    ("[-7 MOD 3]", 2.0), ("[7 MOD -3]", math.fmod(7, -3)), ("[SIN[30] + COS[60]]", 1.0), ("[ATAN[1]/[1]]", 45.0),
    ("[SQRT[16] * ABS[-2]]", 8.0), ("[FIX[2.7] + FUP[2.1] + ROUND[2.5]]", 2 + 3 + 3), ("[1 LT 2 AND 3 GT 2]", 1.0),
    ("[1 EQ 1.0000001]", 1.0), ("[2 XOR 0]", 1.0), ("[EXP[LN[5]]]", 5.0), ("[2 + 3 GT 4]", 1.0),
])
def test_an_expression_is_evaluated_with_linuxcnc_s_operators_and_precedence(expression, expected):
    assert parameter(expression) == pytest.approx(expected, abs=1e-4)


@pytest.mark.parametrize("expression, reason", [
    ("[1 / 0]", "division by zero"), ("[SQRT[-1]]", "SQRT of a negative"), ("[-8 ** 0.5]", "not whole"),
    ("[#<never>]", "read before it is set"), ("[#5410]", "holds a value only the control has"),
    ("[10 ** 400]", "not a finite number"), ("[__import__]", "a number expected"),
])
def test_an_expression_the_control_cannot_evaluate_is_refused(expression, reason):
    with pytest.raises(ExpansionRefused, match=reason):
        parameter(expression)


def test_diameter_radius_inch_and_incremental_positions_become_absolute_mm_diameters():
    lines = moves("G0 X20 Z5", "G8 G0 X12", "G7 G91 G0 X-4 Z-5", "G90 G20 G0 X1 Z0.5")
    assert [(value("X", line), value("Z", line) if "Z" in line else None) for line in lines] == [
        (20.0, 5.0), (2 * 12.0, None), (2 * 12.0 - 4.0, 5.0 - 5.0), (1 * INCH, 0.5 * INCH)]


def test_a_parameter_set_on_a_line_takes_effect_after_the_line():
    assert [value("X", line) for line in moves("#1 = 10", "#1 = 30 G0 X#1", "G0 X#1")] == [10.0, 30.0]


def test_an_arc_given_by_its_centre_is_written_with_its_radius_negative_past_half_a_turn():
    """From X20 Z0 (radius 10) a quarter arc to radius 0 at Z-10 around (r 0, z 0)… and back the long way."""
    quarter, = moves("G0 X20 Z0", "G3 X0 Z-10 I-10 K0 F100")[1:]
    assert value("R", quarter) == pytest.approx(10.0)
    long_way, = moves("G0 X20 Z0", "G2 X0 Z-10 I-10 K0 F100")[1:]
    assert value("R", long_way) == pytest.approx(-10.0)


def test_an_arc_whose_centre_is_not_equidistant_is_refused_as_linuxcnc_refuses_it():
    tolerance = 2 * 0.01 * math.sqrt(2)       # CENTER_ARC_RADIUS_TOLERANCE_MM
    within = f"G2 X0 Z-{10 + tolerance / 2:.4f} I-10 K0 F100"
    assert moves("G0 X20 Z0", within)
    with pytest.raises(ExpansionRefused, match="from its end"):
        moves("G0 X20 Z0", f"G2 X0 Z-{10 + 2 * tolerance:.4f} I-10 K0 F100")


def test_loops_branches_and_calls_follow_linuxcnc_s_o_words():
    body = ["o10 sub", "#<depth> = [#1 * 2]", "G0 X#<depth>", "o10 endsub",
            "#2 = 0", "o20 while [#2 LT 3]", "#2 = [#2 + 1]", "o20 if [#2 EQ 2]", "o20 continue", "o20 endif",
            "o10 call [#2]", "o20 endwhile",
            "o30 do", "G0 X99", "o30 while [0]",
            "o40 repeat [2]", "G0 X50", "o40 endrepeat",
            "o50 if [0]", "G0 X1", "o50 elseif [1]", "G0 X2", "o50 else", "G0 X3", "o50 endif",
            "#1 = 7", "o10 call [4]", "G0 X#1"]
    assert [value("X", line) for line in moves(*body)] == [2.0, 6.0, 99.0, 50.0, 50.0, 2.0, 8.0, 7.0]


def test_g76_makes_the_passes_of_linuxcnc_s_threading_cycle():
    """G76 P1.5 Z-20 I-1 J0.2 K0.9 R2 Q30 H1 in G8 from X10 (radius) Z2 (LinuxCNC gcode G76): the
    peak lies 1 below the drive line, pass n cuts 0.2·n^(1/2) beyond it while short of 0.9, then
    0.9 once and once more for the spring pass; each pass offset along Z by (depth beyond the
    peak)·tan 30°, its cut ending 0.9·tan 30° short of Z-20 less that offset."""
    lines = [line.text for line in expand_linuxcnc([*START, "G8 G0 X10 Z2", "G76 P1.5 Z-20 I-1 J0.2 K0.9 R2 Q30 H1",
                                                    "M2"], LATHE)]
    beyond = [0.2 * math.sqrt(n) for n in range(1, 100) if 0.2 * math.sqrt(n) < 0.9] + [0.9, 0.9]
    tan = math.tan(math.radians(30))
    threads = [line for line in lines if line.startswith("G33")]
    assert [value("X", line) for line in threads] == pytest.approx([2 * (10 - 1 - b) for b in beyond], abs=1e-4)
    assert [value("Z", line) for line in threads] == pytest.approx([-20 + (0.9 - b) * tan for b in beyond], abs=1e-4)
    assert {value("K", line) for line in threads} == {1.5}
    rapids = [line for line in lines if line.startswith("G0 ")]
    backs = rapids[1::3][:len(beyond)]
    assert [value("Z", line) for line in backs] == pytest.approx([2 - b * tan for b in beyond], abs=1e-4)
    assert [value("X", line) for line in backs] == pytest.approx([2 * (10 + 0.9 - b) for b in beyond], abs=1e-4)
    assert rapids[-1] == "G0 X20. Z-20."


@pytest.mark.parametrize("body, reason", [
    (["G0 X10"], "before G7/G8"), (["G0 Z1"], "before G20/G21"), (["G96 S100"], "without a speed clamp D"),
    (["G41"], "compensation"), (["G28"], "home position"), (["G92 Z0"], "offset the verifier cannot see"),
    (["G55"], "work offset"), (["G53 G0 Z0"], "machine coordinates"), (["A1"], "no A axis"),
    (["o<shape> call"], "the file shape.ngc is not in this program"), (["o1 call"], "an o1 sub is not in"),
    (["o1 while [1]"], "without its o1 endwhile"), (["o2 endif"], "closes nothing"), (["/G0 X1"], "block delete"),
    (["o3 sub", "o3 endsub"], "never called"), (["M65 P1"], "HAL output"),
    (["G71 Q1 D1"], "G71 from a position not yet programmed"),
    (["G83 Z-1 R1 Q1"], "G83 outside G17"), (["G73 Z-1 R1 Q1"], "drilling cycle"),
    (["(unclosed"], "without its closing"),
])
def test_what_the_expander_cannot_follow_is_refused_naming_the_construct(body, reason):
    message = refusal(["G18", *body, "M2"])
    assert message is not None and reason in message, message


def test_a_program_without_m2_is_refused():
    message = refusal([*START, "G0 X10 Z2"])
    assert message is not None and "does not end with M2 or M30" in message


def test_lines_after_m2_and_after_the_closing_percent_are_not_run():
    assert moves("G0 X10 Z2", "M2", "G0 X999") == ["G0 X10. Z2."]
    assert refusal(["%", *START, "G0 X10 Z2", "M2", "%", "G0 X999"]) is None


@pytest.mark.parametrize("speed", ["S0", "G96 D3000 S0 M3"])
def test_a_cut_after_a_spindle_speed_of_0_is_refused(speed):
    """S0 with M3 on stops the spindle (G96 S0: a surface speed of 0 m/min, 0 r/min at any X):
    the feed after it would push the tool into a standing bar (adversary 27, finding 2)."""
    message = refusal([*START, "G0 X60 Z5", "G1 X50 F100", speed, "G1 Z-30", "G0 X60", "M5", "M2"])
    assert message is not None and "speed of 0" in message, message


@pytest.mark.parametrize("number", [31, 100, 4999])
def test_a_numbered_global_read_before_the_file_sets_it_is_refused_naming_it(number):
    """#31…#5000 are volatile globals the interpreter does not clear between runs: they hold what the
    last program or MDI left, not 0 (adversary 27, finding 5). Set in the file first, they are read."""
    with pytest.raises(ExpansionRefused, match=f"#{number} is read before the program sets it"):
        parameter(f"[50 - #{number}]")
    (line,) = moves("G8", f"#{number} = 4", f"G0 X[50 - #{number}]")
    assert value("X", line) / 2 == 50 - 4


@pytest.mark.parametrize("mode, reason", [
    ("G64", "G64 without P blends corners without a bound"),
    ("G64 P0.03", "G64 P0.03 blends corners up to 0.03 mm"),
    ("G20 G64 P0.002", f"blends corners up to {0.002 * INCH:g} mm"),
])
def test_blending_corners_beyond_a_thousandth_of_an_inch_is_refused(mode, reason):
    """G64 runs the tool off the programmed path: bare G64 by as much as the speed needs (adversary
    27, finding 7), G64 P by up to P; the turning simulation allows for P up to 0.001 in (0.0254 mm)."""
    message = refusal([*START, mode, "G21 G0 X60 Z5", "G1 X50 F100", "G1 Z-30", "G0 X60", "M5", "M2"])
    assert message is not None and reason in message, message


@pytest.mark.parametrize("mode", ["G61", "G61.1", "G64 P0.0254", "G20 G64 P0.001"])
def test_exact_path_or_blending_within_a_thousandth_of_an_inch_is_accepted(mode):
    assert refusal([*START, mode, "G21 G0 X60 Z5", "G1 X50 F100", "G1 Z-30", "G0 X60", "M5", "M2"]) is None
