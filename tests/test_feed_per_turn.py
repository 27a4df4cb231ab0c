"""Feeds per spindle turn (G95) held to the feed bound (issue 27, the adversary's finding 1): in
G95 F is mm per turn and the tool travels F × n mm/min, so F19999 "per turn" at S800 (16 million
mm/min) and F5 (4,000 mm/min through the part) were written as if F were mm/min. Expected figures
are F × n computed here against the verifier's stated bounds (20,000 mm/min; 2 mm per turn)."""
from __future__ import annotations

import pytest

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program

MAX_FEED = 20000.0          # mm/min, the verifier's feed bound (engine.verifier.words)
MAX_PER_TURN = 2.0          # mm/turn (engine.verifier.feed_mode)
LINUXCNC = Machine("lathe-linuxcnc", "lathe", "linuxcnc", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)
SINUMERIK = Machine("lathe-840d", "lathe", "840d", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)


def linuxcnc(feed: str, speed: str = "G97 S800 M3") -> list[str]:
    return ["G18 G21 G7 G90 G95", "T1 M6 G43", speed, "G0 X60 Z5", f"G1 X50 F{feed}", "G1 Z-30", "G0 X60",
            "G0 Z5", "M5", "M2"]


def sinumerik(feed: str, speed: str = "G97 S800 M3") -> list[str]:
    return ["G18 G71 G90 G40 DIAMON", "T1 D1", speed, "G95", "G0 X60 Z5", f"G1 X50 F{feed}", "G1 Z-30",
            "G0 X60", "G0 Z5", "M5", "M30"]


@pytest.mark.parametrize("program, machine", [(linuxcnc, LINUXCNC), (sinumerik, SINUMERIK)])
def test_a_feed_per_turn_the_insert_can_take_at_a_bounded_speed_is_proved(program, machine):
    assert 0.2 <= MAX_PER_TURN and 0.2 * 800 <= MAX_FEED
    verify_program(program("0.2"), machine, None)


@pytest.mark.parametrize("program, machine", [(linuxcnc, LINUXCNC), (sinumerik, SINUMERIK)])
@pytest.mark.parametrize("feed", ["19999", "5"])
def test_a_feed_per_turn_past_what_an_insert_takes_is_refused(program, machine, feed):
    """F19999 and F5 per turn: both above 2 mm/turn (F19999 × 800 = 15,999,200 mm/min)."""
    assert float(feed) > MAX_PER_TURN
    with pytest.raises(LimitError, match=rf"F{feed} per spindle turn"):
        verify_program(program(feed), machine, None)


def test_a_feed_per_turn_is_held_to_the_feed_bound_at_the_highest_speed_the_spindle_may_turn():
    """F1.5 per turn is an insert's feed, but at the G96 clamp of 4000 r/min the tool travels
    1.5 × 4000 = 6,000 mm/min: within 20,000. F1.5 at S4000 under G97 likewise; the bound bites
    when F × n passes it, which at n ≤ 4000 needs F > 5 mm/turn, already refused above."""
    assert 1.5 * 4000 <= MAX_FEED
    verify_program(sinumerik("1.5", "G96 S200 LIMS=4000 M3"), SINUMERIK, None)
    verify_program(linuxcnc("1.5", "G97 S4000 M3"), LINUXCNC, None)
