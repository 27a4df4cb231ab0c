"""LinuxCNC lathe programs the verifier once accepted but LinuxCNC runs differently (issue 27,
adversary 27c: G64 P0, M70 after M73, a line's order of execution, G7/G8 on a G76 line, G20
programs with G70-G72; docs/reference/linuxcnc-lathe.md §3, §5, §6). Each is refused naming the
construct, or expanded as LinuxCNC's source computes it."""
from __future__ import annotations

import re

import pytest
from helpers.linuxcnc_programs import LATHE, refusal

from engine.verifier.expanders.linuxcnc import expand_linuxcnc

INCH = 25.4
MOTION = ("G0", "G1", "G2", "G3")


def plain(lines: list[str]) -> list[tuple[str, float]]:
    """(plain motion line, its blend tolerance in mm) of a whole program."""
    return [(line.text, line.blend) for line in expand_linuxcnc(lines, LATHE) if line.text.split()[0] in MOTION]


def head(units: str = "G21", diameter: str = "G7", feed: str = "F100", path: str = "G61") -> list[str]:
    return [f"{diameter} G18 {units} G90 G94 G40 {path}", "T1 M6", "G43", "S500 M3", feed]


CUTS = ["G0 X40 Z2", "G1 X30 Z0", "G1 Z-20", "G1 X40", "G0 Z2", "M5", "M2"]


@pytest.mark.parametrize("tolerance", ["P0", "P-1", "P-0.01", "P0.0"])
def test_g64_with_a_zero_or_negative_p_is_refused_as_a_blend_without_bound(tolerance):
    """interp_convert.cc convert_control_mode: P < 0 takes the default tolerance (0 unless the INI
    sets one); tc.c tcFindBlendTolerance reads 0 as none and blends up to a quarter of each move."""
    message = refusal([*head(), f"G64 {tolerance}", *CUTS])
    assert message is not None and f"'G64 {tolerance}'" in message and "zero or negative tolerance" in message, message


def _restore_of(saved_p: str) -> list[str]:
    """G20 G64 P<saved_p>, a sub that saves it (M73) and leaves G61: the return restores the G64."""
    return [*head("G20", feed="F4", path=f"G64 {saved_p}"), "o100 sub", "M73", "G61", "o100 endsub",
            "G0 X1.6 Z0.1", "o100 call", "G1 X1.2 Z0", "G1 Z-1", "G0 X1.6", "M5", "M2"]


def test_a_restored_g64_p_that_prints_as_p0_is_refused():
    """gen_settings writes the saved tolerance as " G64 P%f": 0.0000004 in comes back as
    P0.000000, which LinuxCNC reads as no tolerance."""
    assert f"{0.0000004:f}" == "0.000000"
    message = refusal(_restore_of("P0.0000004"))
    assert message is not None and "'o100 endsub'" in message and "G64 P0.000000" in message, message


def test_a_restored_g64_p_is_the_saved_one_rounded_to_six_decimals_in_its_units():
    """P0.0000126 in is restored as "P0.000013" (%f): the cuts after the return carry that, in mm."""
    lines = plain(_restore_of("P0.0000126"))
    assert [blend for _, blend in lines[-3:]] == pytest.approx([float(f"{0.0000126:f}") * INCH] * 3, abs=1e-12)
    assert lines[-3][1] != pytest.approx(0.0000126 * INCH, abs=1e-9)


@pytest.mark.parametrize("sub", [["M73", "G8", "M70", "G7"], ["M73", "M71", "G8", "M70", "G7"]])
def test_m70_after_m73_in_a_sub_saves_anew_and_the_return_still_restores(sub):
    """convert_m: M70 saves and sets CONTEXT_VALID, only M73 sets RESTORE_ON_RETURN and M71 only
    clears VALID; leave_context restores when both are set. The sub's M70 saved G8 (radius):
    after the return X40 is a radius, Ø80 on the plain line."""
    lines = plain([*head(), "o100 sub", *sub, "o100 endsub", "o100 call", "G0 X40 Z2", "M5", "M2"])
    assert lines[-1][0] == f"G0 X{2 * 40}. Z2."


def test_m71_after_m73_in_a_sub_forgets_the_save_and_nothing_is_restored():
    lines = plain([*head(), "o100 sub", "M73", "G8", "M71", "o100 endsub", "o100 call", "G0 X40 Z2", "M5", "M2"])
    assert lines[-1][0] == f"G0 X{2 * 40}. Z2."      # G8 of the sub stays: no restore without VALID


def test_m70_m5_in_a_sub_after_m73_stops_the_spindle_at_the_return():
    """The restore at endsub is the M70 state (spindle M5): the cuts after the call meet a standing bar."""
    sub = ["o100 sub", "M73", "M5", "M70", "M3", "o100 endsub"]
    message = refusal([*head(), *sub, "G0 X40 Z2", "o100 call", *CUTS[1:]])
    assert message is not None and "spindle stopped" in message, message


def test_g7_on_the_m72_line_is_carried_out_after_the_restore():
    """Order of execution (overview.adoc): M70-M73 before G7/G8. Saved under G8, `G7 M72` ends in
    G7: X30 is a diameter."""
    lines = plain([*head(diameter="G8"), "M70", "G7 M72", "G0 X40 Z2", "G1 X30 Z0", "M5", "M2"])
    assert [text.split(" G94")[0] for text, _ in lines] == ["G0 X40. Z2.", "G1 X30. Z0."]


def test_m73_on_a_g7_line_saves_the_mode_before_the_line_s_g7():
    """`G7 M73` in a sub under G8 saves G8, and the return restores it: X40 after it is a radius."""
    lines = plain([*head(diameter="G8"), "o100 sub", "G7 M73", "o100 endsub", "o100 call", "G0 X40 Z2", "M5", "M2"])
    assert lines[-1][0] == f"G0 X{2 * 40}. Z2."


def test_g21_on_the_m72_line_is_carried_out_after_the_restore_of_g20():
    lines = plain([*head("G20", feed="F4"), "M70", "G21 M72", "G0 X40 Z2", "M5", "M2"])
    assert lines[-1][0] == "G0 X40. Z2."


def test_f_on_a_g21_line_is_read_in_the_units_before_it():
    """F comes before G20/G21 in a line: `G21 F100` after G20 sets 100 in/min, which
    convert_length_units keeps as the same speed in mm (2540 mm/min)."""
    lines = plain([*head("G20", feed="F4"), "G21 F100", "G0 X40 Z2", "G1 X30 Z0", "M5", "M2"])
    found = re.search(r"F([\d.]+)", lines[-1][0])
    assert found is not None and float(found.group(1)) == pytest.approx(100 * INCH), lines


def test_f_on_the_first_line_with_g21_is_refused_its_units_are_the_last_program_s():
    message = refusal(["G7 G18 G21 G90 G94 G40 G61 F100", "T1 M6", "G43", "S500 M3", *CUTS])
    assert message is not None and "line 1" in message and "a length before G20/G21" in message, message


@pytest.mark.parametrize(("before", "switch"), [("G7", "G8"), ("G8", "G7")])
def test_g7_or_g8_switching_the_mode_on_a_g76_line_is_refused(before, switch):
    """convert_lathe_diameter_mode scales I, J, K of a G76 line (×2 to G8, ÷2 to G7) and
    convert_threading_cycle halves them again under G7: the depth cut is not the one written."""
    start = "G0 X24 Z5" if before == "G7" else "G0 X12 Z5"
    message = refusal([*head(diameter=before, feed="F1"), start, f"{switch} G76 P1.5 Z-20 I-1 J0.2 K1",
                       "G0 X30", "M5", "M2"])
    assert message is not None and f"{switch} on a G76 line that switches the diameter mode" in message, message


def test_g7_on_a_g76_line_already_in_g7_is_cut_as_without_it():
    body = ["G0 X24 Z5", "G76 P1.5 Z-20 I-1 J0.2 K1", "G0 X30", "M5", "M2"]
    with_g7 = [*body[:1], "G7 " + body[1], *body[2:]]
    assert plain([*head(feed="F1"), *with_g7]) == plain([*head(feed="F1"), *body])


def _g7x(units: str, profile: list[str], cycle: str) -> list[str]:
    return [*head(units, feed="F4"), "o100 sub", *profile, "o100 endsub", "G0 X1.6 Z0.1", cycle,
            "G0 X2 Z1", "M5", "M2"]


def _numbers(text: str, scale: float = 1.0) -> tuple[str, list[tuple[str, float]]]:
    """A plain motion line's code and its X/Z/R values × scale."""
    return text.split()[0], [(m[1], float(m[2]) * scale) for m in re.finditer(r"([XZR])(-?[\d.]+)", text)]


def _close(inch: list[str], mm: list[str]) -> bool:
    """The G20 run's lines against the G21 run's × 25.4 (LinuxCNC's G20 arithmetic, which is the
    same arithmetic in program units), within the G21 run's 4-decimal print × 25.4 (0.0013 mm)."""
    pairs = [(_numbers(a), _numbers(b, INCH)) for a, b in zip(inch, mm, strict=True)]
    return all(a[0] == b[0] and [n for n, _ in a[1]] == [n for n, _ in b[1]]
               and all(abs(x - y) < 0.002 for (_, x), (_, y) in zip(a[1], b[1], strict=True)) for a, b in pairs)


G70 = (["G1 X0.8 Z0", "G1 Z-0.5", "G1 X1.2", "G1 Z-1.0"], "G70 Q100 X1.6 Z0.1 D0.005 E0.005 P1")
G71 = (["G1 X0.8 Z0", "G1 Z-0.5", "G1 X1.0 Z-0.4995", "G1 Z-1.0"], "G71 Q100 X1.6 Z0.1 D0 I0.05 R0.02")


@pytest.mark.parametrize("case", [G70, G71], ids=["G70 gap 0.005 in", "G71 rise 0.0005 in"])
def test_a_g20_profile_cycle_is_the_same_numbers_in_mm_times_25_4(case):
    """interp_g7x.cc computes in program units with its tolerances as literals (a connecting arc over
    a 0.01 gap, monotonic within 0.001): a G20 cycle's moves are those of the same digits under G21,
    × 25.4. The G70 finishing pass cuts the sharp shoulder (gap 0.005 in < 0.01 in, no arc) and the
    G71 accepts a 0.0005 in rise."""
    profile, cycle = case
    inch = [text for text, _ in plain(_g7x("G20", profile, cycle))]
    assert _close(inch, [text for text, _ in plain(_g7x("G21", profile, cycle))])
    assert not any(text.startswith(("G2", "G3")) for text in inch)


def test_the_g71_rise_in_mm_is_still_refused_as_not_monotonic():
    profile = ["G1 X20 Z0", "G1 Z-12", "G1 X25 Z-11.99", "G1 Z-25"]
    message = refusal([*head(), "o100 sub", *profile, "o100 endsub", "G0 X40 Z2", "G71 Q100 X40 Z2 D0 I1 R0.5",
                       "G0 X50 Z5", "M5", "M2"])
    assert message is not None and "Not monotonic" in message, message


def test_g94_or_g95_on_a_line_of_its_own_sets_the_feed_to_0():
    """convert_feed_mode sets feed_rate 0 with every G94/G95 (interp_convert.cc 2855-2870), and
    a G1 at feed 0 stops LinuxCNC ("Cannot do G1 with zero feed rate")."""
    message = refusal([*head(), "G0 X40 Z2", "G94", *CUTS[1:]])
    assert message is not None and "'G1 X30 Z0'" in message and "G94/G95 (it sets the feed to 0)" in message, \
        message


def test_f_on_the_g95_line_is_set_after_the_feed_mode():
    lines = plain([*head(), "G0 X40 Z2", "G95 F0.1", "G1 X30 Z0", "M5", "M2"])
    assert lines[-1][0].endswith("G95 F0.1")


def test_a_units_change_under_g95_voids_the_feed_until_f_is_stated_again():
    """emccanon.cc SET_FEED_RATE keeps a per-revolution rate as written; after G21 the interpreter
    reads it back unchanged (GET_EXTERNAL_FEED_RATE) and each traverse re-sends it in mm: 0.004 in/rev
    becomes 0.004 mm/rev. A feed move before a new F is refused; with F stated it is that F."""
    start = ["G7 G18 G20 G90 G95 G40 G61", "T1 M6", "G43", "S500 M3", "F0.004", "G0 X1.6 Z0.1"]
    message = refusal([*start, "G21", "G0 X40 Z2", "G1 X30 Z0", "G0 X40", "M5", "M2"])
    assert message is not None and "'G1 X30 Z0'" in message and "a G20/G21 under G95" in message, message
    lines = plain([*start, "G21", "G0 X40 Z2", "G1 X30 Z0 F0.1", "M5", "M2"])
    assert lines[-1][0].endswith("G95 F0.1")
