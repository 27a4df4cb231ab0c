"""840D lathe programs the control runs differently from a first reading (issue 27, adversary 27b:
H8, H9, H10, H15 and the over-refusals of DIV/MOD and of GOTOF): each is either run the control's
way or refused naming the line and the construct.

Expected numbers come from the rules of docs/reference/sinumerik-lathe.md, computed here: a REAL
assigned to an INT rounds a fraction >= 0.5 up (§S2), GOTOF/GOTOB search from the jump in their
direction (§S4), DIV and MOD of whole non-negative numbers are the quotient and remainder (§S3)."""
from __future__ import annotations

import math

import pytest

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program
from engine.verifier.expansion import expand

# lathe-840d of seed_templates/machines.csv: X 0…400 (diameter), Z -600…200, 4000 r/min, G54
LATHE = Machine("lathe-840d", "lathe", "840d", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)
READY = ["G18 G71 G90 G40 DIAMON", "T1 D1", "G97 S500 M3", "G94 F100"]
X_MAX = 400.0


def blocks(body: list[str]) -> list[str]:
    lines = [*READY, *body, "M30"]
    return [line.text for line in expand("840d-lathe", lines, LATHE) if not line.text.startswith(";")][len(READY):]


def refused(body: list[str]) -> str:
    with pytest.raises(LimitError) as raised:
        verify_program([*READY, *body, "M30"], LATHE, "TEST")
    return str(raised.value)


def line_of(body: list[str], text: str) -> str:
    """How a refusal names a line of `body`: its number in the whole program and its text."""
    return f"line {len(READY) + body.index(text) + 1} '{text}'"


def half_up(value: float) -> int:
    """The manual's REAL -> INT rule for a value >= 0: a fraction >= 0.5 rounds up, else down."""
    return math.floor(value) + (1 if value - math.floor(value) >= 0.5 else 0)


# ------------------------------------------------------------------ H9: REAL -> INT rounds half up

def test_a_real_assigned_to_an_int_rounds_a_half_up():
    expected = half_up(2.5) * 10 + half_up(3.5)
    assert blocks(["DEF INT N=5/2", "DEF INT M=7/2", "G0 X=N*10+M Z2"])[0] == f"G0 X{expected} Z2"


def test_a_loop_counted_by_a_rounded_int_runs_its_last_pass():
    """N = 5/2 holds 3 on the control (not Python's 2): three passes put X past the travel."""
    body = ["DEF INT N", "N=5/2", "R1=0", "WHILE R1<N", "R1=R1+1", "ENDWHILE", "G0 X=100+R1*120 Z2",
            "G0 X100 Z50"]
    x = 100 + half_up(2.5) * 120
    assert x > X_MAX
    message = refused(body)
    assert line_of(body, "G0 X=100+R1*120 Z2") in message and f"X{x}" in message


@pytest.mark.parametrize("line", ["DEF INT N=-5/2", "R1=ROUND(-2.5)"])
def test_a_negative_half_rounded_to_a_whole_number_is_refused(line):
    """-2.5 "rounded up" may be -2 or -3: the manual does not say which."""
    message = refused([line])
    assert line_of([line], line) in message and "-2.5" in message and "rounding" in message


# ------------------------------------------------------------------ H10: jumps with duplicate targets

def test_gotob_finds_the_nearest_block_number_backward():
    """Two N100: GOTOB from below finds the nearer one, so R2 grows by 100 on each of 5 passes."""
    body = ["R1=0", "R2=0", "N100 R2=0", "N100 R2=R2+100", "G0 X=R2 Z2", "R1=R1+1", "IF R1<5 GOTOB N100",
            "G0 X100 Z50"]
    message = refused(body)
    assert line_of(body, "G0 X=R2 Z2") in message and f"X{5 * 100}" in message


def test_gotof_to_a_block_number_that_also_stands_earlier_jumps_forward():
    body = ["N100 G0 X50 Z2", "GOTOF N100", "G0 X300 Z2", "N100 G0 X60 Z2"]
    assert blocks(body) == ["G0 X50 Z2", "G0 X60 Z2", "M30"]
    verify_program([*READY, *body, "M30"], LATHE, "TEST")


@pytest.mark.parametrize("jump", ["GOTO N100", "GOTOC N100"])
def test_goto_to_a_block_number_that_stands_twice_is_refused(jump):
    body = ["R1=0", "N100 R1=R1+1", "IF R1>1 GOTOF ENDE", jump, "N100 G0 X600 Z2", "ENDE:", "G0 X100 Z50"]
    message = refused(body)
    first, second = (len(READY) + index + 1 for index, text in enumerate(body) if text.startswith("N100"))
    assert line_of(body, jump) in message and f"N100 stands on lines {first}, {second}" in message


def test_a_section_repeated_from_a_label_that_stands_twice_is_refused():
    body = ["ANFANG: G0 X50 Z2", "ANFANG: G0 X60 Z2", "REPEAT ANFANG P=2"]
    assert line_of(body, "REPEAT ANFANG P=2") in refused(body)


# ------------------------------------------------------------------ H15: assigned and read in one block

@pytest.mark.parametrize("line", ["G0 X=R1 Z2 R1=100", "R1=100 G0 X=R1 Z2", "R1=5 R2=R1*2", "R1=1 R1=2"])
def test_a_block_that_assigns_a_variable_and_reads_it_is_refused(line):
    body = ["R1=900", line, "G0 X100 Z50"]
    message = refused(body)
    assert line_of(body, line) in message and "R1 is assigned in this block" in message


def test_a_parameter_counted_up_from_its_old_value_is_read_once():
    assert blocks(["R1=40", "R1=R1+10 R2=2", "G0 X=R1*R2 Z2"])[0] == f"G0 X{(40 + 10) * 2} Z2"


# ------------------------------------------------------------------ H8: G97 without S after G96

def test_a_thread_after_g97_without_s_after_g96_is_refused():
    """The spindle keeps the r/min G96 last reached (250 m/min at Ø20 is 3979 r/min), not S500."""
    body = ["G96 S250 LIMS=4000", "G95 F0.1", "G0 X20 Z2", "G97", "G33 Z-20 K6", "G0 X100 Z50"]
    message = refused(body)
    assert line_of(body, "G33 Z-20 K6") in message and "G97 without S after G96" in message


def test_g97_with_its_speed_after_g96_cuts_at_that_speed():
    body = ["G96 S250 LIMS=4000", "G95 F0.1", "G0 X20 Z2", "G97 S800", "G33 Z-20 K1.5", "G0 X100 Z50"]
    verify_program([*READY, *body, "M30"], LATHE, "TEST")


def test_a_retract_after_g97_without_s_then_a_speed_is_verified():
    body = ["G96 S250 LIMS=4000", "G95 F0.1", "G0 X20 Z2", "G97", "G0 X100 Z50", "S800", "G1 Z40"]
    verify_program([*READY, *body, "M30"], LATHE, "TEST")


# ------------------------------------------------------------------ DIV and MOD as the manual spells them

def test_div_and_mod_between_blanks_are_evaluated():
    body = ["R2=7", "R1=R2 DIV 2", "R3=7 MOD 3", "G0 X=100+R1*10+R3 Z2"]
    quotient, remainder = divmod(7, 2)[0], divmod(7, 3)[1]
    assert blocks(body)[0] == f"G0 X{100 + quotient * 10 + remainder} Z2"


@pytest.mark.parametrize("line, named", [("R1=-7 MOD 3", "-7 MOD 3"), ("R1=7.5 DIV 2", "7.5 DIV 2"),
                                         ("R1=7 DIV", "DIV is an operator")])
def test_div_and_mod_whose_rule_is_not_confirmed_or_malformed_are_refused_naming_them(line, named):
    message = refused([line])
    assert line_of([line], line) in message and named in message and "is not a word" not in message
