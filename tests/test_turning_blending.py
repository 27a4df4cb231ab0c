"""The blend tolerance of a LinuxCNC program in the turning simulation (issue 27): `G64 P<t>` lets
the control run a move off its programmed path (docs/reference/linuxcnc-lathe.md §3,
engine.simulation.turning.blending), so the proof allows for it: a rapid's blended corner must stay
in air, a cut must stay t clear of the finished part. The clearances are worked out here from
P (0.001 in = 0.0254 mm, the screens' tolerance) and the air tolerance of the material walk."""
from __future__ import annotations

import math

import pytest
from helpers.linuxcnc_programs import LATHE
from msgspec.structs import astuple
from shapely.geometry import Polygon

from engine.simulation.turning.blending import corner
from engine.simulation.turning.follow import FEED, RAPID, Move
from engine.simulation.turning.material import AIR_TOLERANCE_MM, CUT_TOLERANCE_MM, MaterialWalk
from engine.simulation.turning.report import TurningReport
from engine.simulation.turning.run import simulate_turning
from engine.simulation.turning.work import TurningRecords

BLEND = 0.001 * 25.4            # G20 G64 P0.001: the lathe screens' preamble, mm
BAR = {"stock_diameter": 20.0, "stock_z_front": 0.0, "stock_z_back": -60.0}   # r 10, face at Z0


def approach(clearance: float, path_mode: str) -> list[str]:
    """Down the face at rapid `clearance` mm in front of it to X10 (r 5), then a cut into the bar
    along -Z: the corner turns towards the face, so the blend rounds it into the bar's side. The
    path mode is stated in inches, as the screens' preamble does."""
    return ["G18 G20 G7 G90 G94", path_mode, "G21", "T1 M6", "G43", "G97 S500 M3", f"G0 X30 Z{clearance:.4f}",
            f"G0 X10 Z{clearance:.4f}", "G1 Z-5 F100", "G0 X30", "M5", "M2"]


def findings(lines: list[str]) -> list[str]:
    return [finding.message for finding in simulate_turning(lines, BAR, {}, LATHE, "blend").findings]


def test_a_rapid_whose_blended_corner_reaches_the_bar_is_refused_and_one_clear_of_it_passes():
    """The corner may be rounded anywhere within P of the path inside its angle: the part of it
    along the rapid lies between Z=c-P and Z=c, which enters the bar's face (less the air tolerance)
    when c < P - AIR_TOLERANCE_MM."""
    near, far = (BLEND - AIR_TOLERANCE_MM) / 2, 2 * BLEND
    assert near < BLEND - AIR_TOLERANCE_MM < far
    found = findings(approach(near, "G64 P0.001"))
    assert found and "the corner blended into this move at rapid" in found[0], found
    assert findings(approach(far, "G64 P0.001")) == []
    assert findings(approach(near, "G61")) == []           # on the exact path the same rapid is clear


def test_the_blended_corner_lies_inside_the_angle_within_the_tolerance():
    """Rapid down -X (r 15 → 5) at Z1, then a cut along -Z: inside the angle means Z ≤ 1 and r ≥ 5."""
    rapid = Move(1, "G0", RAPID, [(1.0, 15.0), (1.0, 5.0)], None, None, False, None, True, None, BLEND)
    cut = Move(2, "G1", FEED, [(1.0, 5.0), (-5.0, 5.0)], None, None, False, None, True, None, BLEND)
    region = corner(rapid, cut)
    z0, r0, z1, r1 = region.bounds
    assert (z0, r0, z1, r1) == pytest.approx((-5.0, 5.0, 1.0, 15.0))
    assert region.area == pytest.approx(BLEND * 10 + BLEND * 6 - BLEND * BLEND)     # two strips, one overlap
    assert corner(rapid, cut, RAPID).area == pytest.approx(BLEND * 10)               # the rapid's strip
    straight = Move(2, "G0", RAPID, [(1.0, 5.0), (1.0, 2.0)], None, None, False, None, True, None, BLEND)
    assert corner(rapid, straight) is None                                           # in line: no corner
    exact = Move(2, "G1", FEED, [(1.0, 5.0), (-5.0, 5.0)], None, None, False, None, True, None, 0.0)
    assert corner(None, cut) is None and corner(Move(*astuple(rapid)), exact) is not None


def finish_pass(clearance: float, blend: float) -> list[str]:
    """A pass along -Z at `clearance` mm above a drawn part's Ø16 (r 8), in a Ø20 blank."""
    part = Polygon([(-30, -8), (0, -8), (0, 8), (-30, 8)])
    records = TurningRecords(part, None, 0.0, -30.0, 8.0, (60.0, 50.0))
    report = TurningReport("finish")
    walk = MaterialWalk(records, Polygon([(-40, -10), (2, -10), (2, 10), (-40, 10)]), report, 0.0)
    r = 8.0 + clearance
    walk.take(Move(1, "G1", FEED, [(2.0, r), (-25.0, r)], None, 500.0, False, 0.1, False, None, blend))
    return [finding.message for finding in report.findings]


def test_a_blended_cut_that_could_run_into_the_part_is_refused():
    """A cut may run anywhere within P of its path: on the profile (clearance 0) it could cut P deep,
    past the cut tolerance, along the 25 mm over the part (Z0 … -25) and on in front of its face as
    far as P reaches round the corner of the part less the cut tolerance (at Z-CUT, R8-CUT: the
    pass runs CUT above it); P clear of the part, it cannot."""
    assert BLEND > CUT_TOLERANCE_MM
    found = finish_pass(0.0, BLEND)
    assert len(found) == 1 and f"G64 P{BLEND:g} mm" in found[0], found
    length = 25.0 - CUT_TOLERANCE_MM + math.sqrt(BLEND ** 2 - CUT_TOLERANCE_MM ** 2)
    assert f"for {length:.3f} mm" in found[0]
    assert finish_pass(0.0, 0.0) == []                         # the exact path (G61) on the profile
    assert finish_pass(BLEND - CUT_TOLERANCE_MM + 0.001, BLEND) == []
    assert finish_pass(BLEND - CUT_TOLERANCE_MM - 0.001, BLEND) != []
