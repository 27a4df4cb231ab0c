"""G83 peck drilling on a lathe's axis and T0 M6 (issue 27), read as LinuxCNC makes them: the
expected moves are worked out here from src/emc/rs274ngc/interp_cycles.cc convert_cycle_g83 (feed
Q deeper, rapid to R, rapid back to the peck clearance above the bottom just drilled; the last
peck to the bottom Z, then the clear level: the initial Z in G98, R in G99)."""
from __future__ import annotations

import pytest
from helpers.linuxcnc_moves import moves

from engine.verifier.expansion import ExpansionRefused

START = ["G18 G21 G7 G90 G94", "T1 M6", "G43", "G97 S500 M3"]
DRILL = ["G17 G95 F0.1", "G0 X0 Z10"]


def reference_g83(initial: float, r: float, bottom: float, peck: float, clearance: float,
                  clear: float) -> list[tuple[str, float]]:
    """The Z moves of a G83 started at `initial` ≥ R, from interp_cycles.cc, written out plainly."""
    out: list[tuple[str, float]] = [("G0", r)] if initial > r else []
    depth = r - peck
    while depth > bottom:
        out += [("G1", depth), ("G0", r), ("G0", depth + clearance)]
        depth -= peck
    return [*out, ("G1", bottom), ("G0", clear)]


def z_moves(lines: list[str]) -> list[tuple[str, float]]:
    return [(line.split()[0], float(line.split()[1][1:])) for line in lines]


@pytest.mark.parametrize("retract, clear", [("G98", 10.0), ("G99", 2.0)])
def test_g83_pecks_along_z_on_the_axis_and_retracts_to_its_level(retract, clear):
    lines = moves(*DRILL, f"{retract} G83 Z-11 R2 Q4", "G80")
    assert lines[0] == "G0 X0. Z10."
    # depths 2-4=-2, -6, -10, then the bottom -11; 1 mm peck clearance (metric default)
    assert z_moves(lines[1:]) == reference_g83(10.0, 2.0, -11.0, 4.0, 1.0, clear)
    assert all(line.endswith("G95 F0.1") for line in lines[1:] if line.startswith("G1"))


def test_g83_takes_the_peck_clearance_d_of_the_block():
    lines = moves(*DRILL, "G98 G83 Z-5 R1 Q3 D0.5", "G80")
    assert z_moves(lines[1:]) == reference_g83(10.0, 1.0, -5.0, 3.0, 0.5, 10.0)


def test_an_x0_in_the_g83_block_with_the_tool_on_the_axis_drills_as_without_it():
    """A new user's G83 X0.000 after G0 X0: it moves nothing, so the pecks are those of the block
    without its X (reference_g83 of the peck rule); an X off where the tool stands is refused."""
    assert moves(*DRILL, "G98 G83 X0.000 Z-5 R1 Q3", "G80") == moves(*DRILL, "G98 G83 Z-5 R1 Q3", "G80")
    with pytest.raises(ExpansionRefused, match="G83 with an X the tool is not at"):
        moves("G17 G95 F0.1", "G0 X0 Z10", "G98 G83 X4 Z-5 R1 Q3")


@pytest.mark.parametrize("body, reason", [
    (["G17 G95 F0.1", "G0 X10 Z10", "G98 G83 Z-5 R1 Q3"], "off the lathe's axis"),
    (["G95 F0.1", "G0 X0 Z10", "G98 G83 Z-5 R1 Q3"], "outside G17"),
    (["G17 G95 F0.1", "G0 X0 Z10", "G83 Z-5 R1 Q3"], "before G98/G99"),
    (["G17 G95 F0.1", "G0 X0 Z10", "G98 G83 Z-5 R1 Q0"], "Q .peck, above 0."),
    (["G17 G95 F0.1", "G0 X0 Z10", "G98 G83 Z5 R1 Q1"], "R below the bottom Z"),
    (["G17 G95 F0.1", "G0 X0 Z10", "G98 G83 Z-5 R1 Q1", "G80 Z3"], "axis words after G80"),
    (["G17 G95 F0.1", "G0 X0 Z10", "G98 G83 Z-5 R1 Q1 D-1"], "negative peck clearance"),
    (["G17 G95 F0.1", "G0 X0 Z10", "G98 G81 Z-5 R1"], "G81 is a drilling cycle without a lathe model"),
])
def test_a_drilling_cycle_the_lathe_cannot_make_as_written_is_refused(body, reason):
    with pytest.raises(ExpansionRefused, match=reason):
        moves(*body)


def test_t0_m6_unloads_the_tool_and_rapids_may_follow():
    lines = moves("G0 X20 Z5", "M5", "G49", "T0 M6", "G0 X40 Z50")
    assert lines[-1] == "G0 X40. Z50."


@pytest.mark.parametrize("cut", ["G1 X10 F100", "G2 X10 Z0 R5 F100", "G33 Z-5 K1"])
def test_a_cut_after_t0_m6_is_refused_until_a_tool_is_changed_in(cut):
    with pytest.raises(ExpansionRefused, match="no tool in the spindle"):
        moves("G0 X20 Z5", "M5", "T0 M6", cut)
    assert moves("G0 X20 Z5", "M5", "T0 M6", "T2 M6", "G43", "M3", "G1 X10 F100")[-1].startswith("G1 X10.")
