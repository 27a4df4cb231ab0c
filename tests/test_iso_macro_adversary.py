"""Adversary 27c's Fanuc custom macro B and machine-record findings (issue 27): programs the ISO
lathe verifier accepted although a Fanuc runs them otherwise or stops with an alarm. Each smallest
program is refused naming its construct, or, where the rule is modelled, the plain moves carry the
values computed here from the rule (docs/reference/iso-lathe.md, "Custom macro B")."""
from __future__ import annotations

import math

import psycopg
import pytest
from helpers.iso_real_programs import FANUC_0T, cut, plain_moves, verdict
from msgspec.structs import replace

from engine.machines.records import load_machine
from engine.verifier.expanders.iso import expand_iso
from engine.verifier.expansion import ExpansionRefused


def fix(value: float) -> float:
    """Fanuc FIX: the fraction dropped (towards zero)."""
    return float(int(value))


def fup(value: float) -> float:
    """Fanuc FUP: a fraction raises the magnitude (away from zero)."""
    return math.copysign(math.ceil(abs(value)), value)


@pytest.mark.parametrize("value", [-1.2, -1.7, 1.2, 1.7, -2.0])
def test_fix_goes_towards_zero_and_fup_away_from_zero(conn, value):
    body = [f"#1={value}", "#2=FIX[#1]", "#3=FUP[#1]", "G01 X[120.+#2*10.] Z[#3*10.-30.] F0.2"]
    moves = plain_moves(load_machine(conn, FANUC_0T), cut(body))
    assert moves == [pytest.approx((120 + fix(value) * 10, fup(value) * 10 - 30))]


def test_round_inside_a_word_is_refused_and_in_an_assignment_is_a_whole_number(conn):
    message = verdict(conn, FANUC_0T, cut(["#1=51.2345", "G01 X[ROUND[#1]+50.] Z-10. F0.3"]))
    assert message is not None and "ROUND inside the X word" in message, message
    moves = plain_moves(load_machine(conn, FANUC_0T), cut(["#1=51.5", "#2=ROUND[#1]", "G01 X[#2+50.] Z-10. F0.3"]))
    assert moves == [pytest.approx((math.floor(51.5 + 0.5) + 50, -10.0))]


@pytest.mark.parametrize("body, construct", [
    (["#1=0", "GOTO 10", "WHILE [#1 LT 2] DO 1", "N10 #1=#1+1", "G01 X[120.-#1] Z-10. F0.3", "END 1"],
     "GOTO 10 jumps into the loop"),
    (["#1=0", "#2=0", "WHILE [#1 LT 2] DO 1", "#1=#1+1", "WHILE [#2 LT 2] DO 2", "#2=#2+1",
      "G01 X[120.-#1] Z-10. F0.3", "END 1", "END 2"], "the DO ranges overlap"),
    (["#1=0", "WHILE [#1 LT 2] DO 1", "#2=0", "WHILE [#2 LT 2] DO 1", "#2=#2+1", "END 1", "#1=#1+1",
      "END 1"], "DO 1 inside a loop DO 1"),
    (["END 1"], "END 1 without its WHILE"),
])
def test_a_loop_structure_a_fanuc_alarms_on_is_refused_naming_it(conn, body, construct):
    message = verdict(conn, FANUC_0T, cut(body))
    assert message is not None and construct in message, message


def test_a_jump_out_of_a_loop_is_followed(conn):
    body = ["#1=0", "WHILE [#1 LT 5] DO 1", "#1=#1+1", "IF [#1 EQ 2] GOTO 20", "END 1",
            "N20 G01 X[120.-#1] Z-10. F0.3"]
    assert plain_moves(load_machine(conn, FANUC_0T), cut(body)) == [pytest.approx((118.0, -10.0))]


@pytest.mark.parametrize("body, construct", [
    (["#1=[1 LT 2]"], "the TRUE/FALSE of a comparison is not a number"),
    (["#1=[1 LT 2]+1"], "+ with the TRUE/FALSE of a comparison"),
    (["#1=1", "IF [#1] GOTO 10", "N10 G01 X110. Z-10. F0.3"], "[#1] is not a comparison"),
    (["#1=1", "WHILE [#1] DO 1", "END 1"], "[#1] is not a comparison"),
    (["#1=SIN[[[[[[30.]]]]]]"], "brackets nested 6 deep: Fanuc allows 5 (alarm 118)"),
])
def test_a_form_a_fanuc_rejects_is_refused_naming_it(conn, body, construct):
    message = verdict(conn, FANUC_0T, cut(body))
    assert message is not None and construct in message, message


def test_five_bracket_levels_are_evaluated(conn):
    moves = plain_moves(load_machine(conn, FANUC_0T), cut(["#1=SIN[[[[[30.]]]]]", "G01 X[110.+#1] Z-10. F0.3"]))
    assert moves == [pytest.approx((110 + math.sin(math.radians(30)), -10.0))]


@pytest.mark.parametrize("body, construct", [
    (["IF [#1 EQ #0] THEN #1=110."], "#1 is read before this program sets it"),
    (["#1=#0"], "#0 is always vacant"),
])
def test_a_vacant_variable_stays_refused(conn, body, construct):
    """Fanuc's own vacant rules were not found (the corpus has Mitsubishi's and third parties'):
    fail closed."""
    message = verdict(conn, FANUC_0T, cut(body))
    assert message is not None and construct in message, message


def test_the_seeded_record_supplies_no_units_and_a_program_without_them_is_refused(conn):
    machine = load_machine(conn, FANUC_0T)
    assert machine.power_on is not None and not {"G20", "G21"} & set(machine.power_on.split())
    lines = ["%", "O0002", "G50 S2000", "T0101", "G97 S800 M03", "G00 X122. Z2.", "G01 X118. Z-45. F0.3",
             "G00 X200. Z150.", "M30", "%"]
    message = verdict(conn, FANUC_0T, lines)
    assert message is not None and "motion before G21 (mm) is stated" in message, message


@pytest.mark.parametrize("power_on, construct", [
    ("G18 G21 G40 G97 G99", "power_on lists G21: a Fanuc keeps the units"),
    ("G18 G21 G20 G40 G97 G99", "power_on lists G21 and G20"),
    ("G18 G40 G90 G97 G99", "power_on lists G90, which on G-code system A is the turning cycle"),
    ("G18 G40 G97 G98 G99", "power_on lists G98 and G99, one modal group"),
])
def test_a_power_on_the_control_cannot_be_in_is_refused_by_the_record_check(conn, power_on, construct):
    machine = replace(load_machine(conn, FANUC_0T), power_on=power_on)
    with pytest.raises(ExpansionRefused, match=construct):
        expand_iso(cut(["G01 X118. Z-45. F0.3"]), machine)


def test_the_database_refuses_units_in_power_on(conn):
    with pytest.raises(psycopg.errors.CheckViolation):
        conn.execute("UPDATE machine SET power_on = 'G18 G21 G40' WHERE name = %s", (FANUC_0T,))
