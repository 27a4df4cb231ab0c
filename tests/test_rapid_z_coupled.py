"""Rapid Z while coupled (issue 14): with Z a leading axis of the EG coupling (the helical
differential), a G0 Z move turns the table by k_Z·rapid_rate degrees per minute on top of the
generating ratio. The verifier refuses a program whose table would then pass the machine's
table_speed_max, naming the block; the rapid rate is the machine record's (`rapid_rate`).

Expected outcomes from reference §A5, computed here: n_C = (z0/z2)·n_B + k_Z·v_Z/360 r/min,
k_Z in degrees of C per mm, v_Z in mm/min; G0 moves each axis at the rapid rate."""
from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program

TABLE_MAX = 120.0
PRELUDE = ["%_N_RAPID_MPF", ";$PATH=/_N_MPF_DIR", "G90 G71 G94", "G54", "G25 X50.000 Y-30.000 Z-200.000",
           "G26 X250.000 Y30.000 Z100.000", "WALIMON"]


def hobber(rapid_rate: float) -> Machine:
    return Machine("hobber-test", "hobber", "840d", 20, 320, -80, 80, -350, 150, 1000, TABLE_MAX, 4,
                   rapid_rate=rapid_rate)


def table_speed(speed: float, teeth: int, factor: float, velocity: float) -> float:
    return speed / teeth + factor * velocity / 360.0


def coupled(teeth: int, factor: float, speed: int, *blocks: str) -> list[str]:
    return PRELUDE + ["G0 X200.000 Z50.000", "G0 Y0.000", "EGDEF(C,B,1,Z,1)",
                      f'EGON(C,"FINE",B,-1,{teeth},Z,{factor:.6f},1)',
                      f"M3 S{speed}", *blocks, "M5", "EGOFS(C)", "EGDEL(C)", "M30"]


def verdict(machine: Machine, lines: list[str]) -> bool:
    try:
        verify_program(lines, machine, "RAPID")
    except LimitError:
        return False
    return True


@settings(max_examples=300, deadline=None)
@given(teeth=st.integers(5, 150), speed=st.integers(1, 1000), factor=st.floats(0.0, 20.0),
       rapid=st.sampled_from([2000.0, 5000.0, 8000.0, 15000.0, 30000.0]))
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_rapid_z_is_accepted_exactly_when_the_table_stays_within_its_maximum(teeth, speed, factor, rapid):
    k = float(f"{factor:.6f}")
    table = table_speed(speed, teeth, k, rapid)
    assume(abs(table - TABLE_MAX) > 1e-6 and speed / teeth < TABLE_MAX)
    lines = coupled(teeth, k, speed, "G0 Z-20.000")
    assert verdict(hobber(rapid), lines) == (table <= TABLE_MAX), (table, lines)


def test_the_refusal_names_the_g0_block_and_the_rapid_term():
    rapid, k = 8000.0, 5.0
    assert table_speed(246, 19, k, rapid) > TABLE_MAX
    lines = coupled(19, k, 246, "G0 Z-20.000")
    with pytest.raises(LimitError) as refused:
        verify_program(lines, hobber(rapid), "RAPID")
    message = str(refused.value)
    assert "\n" not in message
    assert f"line {lines.index('G0 Z-20.000') + 1} 'G0 Z-20.000'" in message, message
    assert f"the table turns at {table_speed(246, 19, k, rapid):.1f} r/min" in message
    assert f"G0 Z {k:g}°/mm × {rapid:g} mm/min" in message, message


def test_the_same_move_at_a_bounded_feed_passes():
    rapid, k = 8000.0, 5.0
    feed = math.floor((TABLE_MAX - 246 / 19) * 360 / k)               # the fastest Z the table allows
    assert table_speed(246, 19, k, feed) <= TABLE_MAX < table_speed(246, 19, k, rapid)
    assert verdict(hobber(rapid), coupled(19, k, 246, f"G1 Z-20.000 F{feed:.1f}"))


def test_a_rapid_x_or_a_rapid_z_after_uncoupling_adds_nothing():
    rapid, k = 30000.0, 5.0
    assert table_speed(246, 19, k, rapid) > TABLE_MAX
    assert verdict(hobber(rapid), coupled(19, k, 246, "G0 X150.000"))
    after = coupled(19, k, 246)
    after.insert(after.index("EGDEL(C)") + 1, "G0 Z-20.000")
    assert verdict(hobber(rapid), after)


def test_a_slower_rapid_rate_lets_the_same_program_pass():
    k = 5.0
    slow = math.floor((TABLE_MAX - 246 / 19) * 360 / k)
    lines = coupled(19, k, 246, "G0 Z-20.000")
    assert verdict(hobber(float(slow)), lines)
    assert not verdict(hobber(float(slow + 100)), lines)


def test_a_rapid_z_to_where_z_already_stands_adds_no_table_term():
    """`G0 Z50.000` with Z at 50 moves nothing, so it cannot turn the table by k_Z·v_Z; a
    Z that does move at the same rapid would pass the maximum (§A5)."""
    rapid, k = 8000.0, 5.0
    assert table_speed(246, 19, k, rapid) > TABLE_MAX
    assert verdict(hobber(rapid), coupled(19, k, 246, "G0 Z50.000"))
    assert not verdict(hobber(rapid), coupled(19, k, 246, "G0 Z49.000"))
