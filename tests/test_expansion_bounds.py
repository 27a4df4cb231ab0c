"""The expanders' bounds hold in practice (issue 27, the adversary's finding 5): a LinuxCNC G76
asking for 99,999,999 spring passes was expanded pass by pass until the process ran out of memory
(killed after 4 minutes, no message); it is refused at once, naming the word, with exit 1."""
from __future__ import annotations

import pytest

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program
from engine.verifier.expanders.cycles import MAX_PASSES

LATHE = Machine("lathe-linuxcnc", "lathe", "linuxcnc", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)


def thread(springs: int) -> list[str]:
    """An M20 × 1.5 outside thread (LinuxCNC G76: P pitch, I from the drive line, J first cut,
    K full depth; H spring passes) on a Ø20 bar, S300: 1.5 × 300 = 450 mm/min along Z."""
    return ["G18 G21 G7 G90 G95", "T1 M6 G43", "G97 S300 M3", "G0 X22 Z5",
            f"G76 P1.5 Z-20 I-1 J0.2 K0.92 H{springs}", "G0 X40 Z50", "M5", "M2"]


def test_a_thread_with_a_few_spring_passes_is_proved():
    verify_program(thread(2), LATHE, None)


def test_a_thread_asking_for_more_spring_passes_than_the_bound_is_refused_at_once():
    with pytest.raises(LimitError, match=rf"more than {MAX_PASSES} spring passes"):
        verify_program(thread(99_999_999), LATHE, None)    # the old code never returned
