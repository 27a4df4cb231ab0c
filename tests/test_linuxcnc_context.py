"""M70–M73 in the LinuxCNC expander (engine.verifier.expanders.linuxcnc_context, issue 27): the
modes saved and restored as LinuxCNC's `restore_settings` does (docs/reference/linuxcnc-lathe.md
§6), the expected values worked out here from those rules."""
from __future__ import annotations

import pytest
from helpers.linuxcnc_moves import START, moves
from helpers.linuxcnc_programs import LATHE, refusal

from engine.verifier.expanders.linuxcnc import expand_linuxcnc
from engine.verifier.expansion import ExpansionRefused

INCH = 25.4
# a sub that saves the modes with M73, then changes units, diameter and distance modes, the
# spindle and the coolant (and cuts: X20 in radius, incremental, is 20 in below where it stands)
CHANGER = ["o10 sub", "M73", "G20 G8 G91", "G97 S800 M3 M8", "o10 endsub"]
CUT = ["G0 X60 Z5", "G1 X50 F100", "G1 Z-30", "G0 X60"]


def restored(*lines: str) -> list[str]:
    """The plain lines the sub's return makes (its `o10 endsub` line)."""
    return [line.text for line in expand_linuxcnc([*lines, "M2"], LATHE) if line.source == "o10 endsub"]


def test_the_modes_a_sub_changes_after_its_m73_are_back_after_its_return():
    """G21 G7 G90 in the caller: after the call X50 Z5 is 50 mm on the diameter, absolute; had the
    sub's G20 G8 G91 stayed, it would be 2 × 50 in and 5 in further on."""
    assert moves(*CHANGER, "o10 call", "G0 X50 Z5") == ["G0 X50. Z5."]
    assert moves(*CHANGER[:1], *CHANGER[2:], "G0 X0 Z0", "o10 call", "G0 X1 Z1") == [
        "G0 X0. Z0.", f"G0 X{2 * 1 * INCH:g} Z{1 * INCH:g}"]        # without M73 the sub's modes hold


def test_a_spindle_off_at_the_m73_is_off_after_the_return_and_the_next_cut_is_refused():
    start = [line for line in START if "M3" not in line]       # the spindle never started
    lines = [*start, *CHANGER, "o10 call", *CUT, "M2"]
    assert restored(*start, *CHANGER, "o10 call") == ["G21", "M5", "M9"]   # units, spindle and coolant off
    message = refusal(lines)
    assert message is not None and "a cut with the spindle stopped" in message and "G1 X50 F100" in message, message
    assert refusal([*start, *CHANGER, "o10 call", "S500 M3", *CUT, "M5", "M2"]) is None   # started again: cut
    # the restore wrote S0 (never set before the M73): M3 alone would turn a spindle at 0 r/min
    message = refusal([*start, *CHANGER, "o10 call", "M3", *CUT, "M5", "M2"])
    assert message is not None and "M3 with S0 in force" in message, message


def test_a_spindle_on_at_the_m73_turns_again_after_a_sub_that_stopped_it():
    sub = ["o10 sub", "M73", "M5", "o10 endsub"]
    assert restored(*START, *sub, "o10 call") == ["G97 S500.", "M3"]     # S%.0f and the spindle, as saved
    assert refusal([*START, *sub, "o10 call", *CUT, "M5", "M2"]) is None


def test_m70_saves_and_m72_restores_at_the_same_level_m71_forgets():
    assert moves("M70", "G20 G91", "M72", "G0 X50 Z5") == ["G0 X50. Z5."]
    with pytest.raises(ExpansionRefused, match="M72 with no modes saved"):
        moves("M70", "M71", "G20", "M72")
    with pytest.raises(ExpansionRefused, match="M72 with no modes saved"):
        moves("o10 sub", "M72", "o10 endsub", "M70", "o10 call")    # a call level of its own
    # M71 in a sub after its M73: the return restores nothing, the sub's G20 stays
    assert moves("o10 sub", "M73", "G20", "M71", "o10 endsub", "o10 call", "G0 X1 Z1") == [
        f"G0 X{1 * INCH:g} Z{1 * INCH:g}"]


def test_the_feed_comes_back_to_a_tenth_of_a_unit_as_linuxcnc_writes_it():
    """restore_settings writes " F%.1f" in the restored units: F0.004 in/rev comes back as F0.0, and
    the next feed move without its own F is refused; F123.456 mm/min comes back as F123.5."""
    sub = ["o10 sub", "M73", "F0.008", "o10 endsub"]
    with pytest.raises(ExpansionRefused, match="a feed move with no F in force"):
        moves("G20 G95 F0.004", *sub, "o10 call", "G1 X1 Z0")
    (line,) = moves("G21 G94 F123.456", *sub, "o10 call", "G1 X50")
    assert line.endswith(f"G94 F{float(f'{123.456:.1f}'):g}")


def test_a_restore_that_would_turn_g96_on_without_its_clamp_is_refused():
    """G96 comes back as a bare G96, which LinuxCNC runs with no speed limit (convert_spindle_mode: 1e30)."""
    with pytest.raises(ExpansionRefused, match="without its clamp D"):
        moves("G96 D2000 S200", "o10 sub", "M73", "G97 S800", "o10 endsub", "o10 call")


def test_a_restore_that_turns_the_spindle_on_at_s0_is_refused():
    """M3 saved before any S: the restore writes S0 with M3, a standing spindle that the program cuts with."""
    start = [line for line in START if "M3" not in line]
    with pytest.raises(ExpansionRefused, match=r"turns the spindle on \(M3\) at S0"):
        moves("M3", "o10 sub", "M73", "S800 M5", "o10 endsub", "o10 call", start=start)
