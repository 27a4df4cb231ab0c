"""LinuxCNC programs the verifier once accepted but LinuxCNC runs differently (issue 27, adversary
27b; docs/reference/linuxcnc-lathe.md §6): a repeat count is rounded, not cut (H11)."""
from __future__ import annotations

import math

import pytest
from helpers.linuxcnc_moves import moves


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

