"""LinuxCNC programs the verifier once accepted but LinuxCNC runs differently (issue 27, adversary
27b findings H11, H12, H18; docs/reference/linuxcnc-lathe.md §2, §6): a repeat count is rounded,
not cut; #1…#30 of the main program hold what the last program left; a sub is defined before it
is called."""
from __future__ import annotations

import math

import pytest
from helpers.linuxcnc_moves import START, moves
from helpers.linuxcnc_programs import refusal


def nearbyint(value: float) -> int:
    """C's nearbyint in the default rounding mode (FE_TONEAREST): the nearest whole number, a
    value half-way between two going to the even one."""
    low = math.floor(value)
    rest = value - low
    return int(low) + (1 if rest > 0.5 or (rest == 0.5 and low % 2 == 1) else 0)


@pytest.mark.parametrize("count", [2.6, 2.5, 3.5, 1.5, 0.6, 0.5, 0.4, 3.0, 0.0, -0.6])
def test_a_repeat_runs_its_body_the_count_rounded_as_linuxcnc_rounds_it(count):
    """interp_o_word.cc: repeat_count = round_to_int(value) = (int)nearbyint(value); 0 or less
    skips the body. 2.6 runs 3 times (it ran 2), 0.6 once (it was skipped)."""
    passes = max(0, nearbyint(count))
    lines = moves("#<n> = 0", f"o10 repeat [{count}]", "#<n> = [#<n> + 1]", "G0 X#<n> Z2", "o10 endrepeat")
    assert lines == [f"G0 X{n}. Z2." for n in range(1, passes + 1)]


@pytest.mark.parametrize("number", [1, 30])
def test_a_main_program_reading_a_numbered_parameter_below_31_before_setting_it_is_refused(number):
    """Outside a call #1…#30 are not cleared between runs: X[#1 + 50] moves where the last
    program's #1 says, not to X50."""
    message = refusal([*START, f"G0 X[#{number} + 50] Z2", "G0 X100 Z50", "M5", "M2"])
    assert message is not None and f"#{number} is read in the main program before the program sets it" in message, \
        message


def test_inside_a_call_an_argument_not_passed_is_0_and_the_main_program_s_value_returns_after():
    """A call zeroes #1…#30 it is not given (interp_read.cc) and restores the caller's on return."""
    lines = moves("o10 sub", "G0 X[#1 + 50] Z[#2 + 2]", "o10 endsub", "#1 = 7", "o10 call", "o10 call [4]",
                  "G0 X#1 Z2")
    assert lines == ["G0 X50. Z2.", "G0 X54. Z2.", "G0 X7. Z2."]


def test_a_call_before_its_sub_is_defined_is_refused_naming_the_call():
    """o-code.adoc: subs may only be called after they are defined; LinuxCNC otherwise runs a file
    100.ngc from its SUBROUTINE_PATH first, which the verifier does not have."""
    message = refusal([*START, "G0 X50 Z2", "o100 call", "G0 X100 Z50", "M5", "M2",
                       "o100 sub", "G0 X60", "o100 endsub"])
    assert message is not None and "'o100 call'" in message and "before its o100 sub" in message, message


def test_a_sub_may_call_one_defined_after_it_once_both_are_read():
    """The control's table of subs fills as it reads the definitions: o1 calling o2 works when o1
    is called after o2's definition, and is refused when called before it."""
    late = ["o2 sub", "G0 X60 Z2", "o2 endsub"]
    first = ["o1 sub", "o2 call", "o1 endsub"]
    assert moves(*first, *late, "o1 call") == ["G0 X60. Z2."]
    message = refusal([*START, *first, "o1 call", *late, "M5", "M2"])
    assert message is not None and "'o2 call'" in message and "before its o2 sub" in message, message
