"""Property (issue 26): random lathe programs in both dialects, with rapids and feeds placed at
random relative to the blank and the part; no program whose path enters material at rapid or cuts
the finished profile is accepted, and none that keeps clear of both by a margin is refused for it.

The truth is computed here on its own, without shapely and without the simulation's code: points
sampled every SAMPLE_MM along each move are tested against the stepped shaft and the Ø36 blank,
whose bar runs on behind its back end into the chuck (less the columns above earlier feeds: an
outside tool's body stands radially above its tip, design
notes §8) with a margin MARGIN_MM, so a point is "surely in material", "surely in air" or too
close to an edge to say (then the move says nothing either way)."""
from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.machines.records import Machine
from engine.simulation.turning.run import simulate_turning

STEPS = [(0.0, -20.0, 10.0), (-20.0, -40.0, 15.0)]    # (z front, z back, radius) of the part, mm
STOCK = {"stock_diameter": 36.0, "stock_z_front": 2.0, "stock_z_back": -42.0}
BLANK_RADIUS, BLANK_FRONT = 18.0, 2.0      # the back end -42 does not bound it: the bar runs on
CHANGE_X, CHANGE_Z = 80.0, 30.0
MARGIN_MM = 0.05
SAMPLE_MM = 0.02
GEOMETRY = ("a rapid through material", "a cut into the finished part")
PARAMS = {
    "profile": [["line", 0.0, 0.0, 0.0, 10.0], ["line", 0.0, 10.0, -20.0, 10.0], ["line", -20.0, 10.0, -20.0, 15.0],
                ["line", -20.0, 15.0, -40.0, 15.0], ["line", -40.0, 15.0, -40.0, 0.0]],
    "tool_change_x": CHANGE_X, "tool_change_z": CHANGE_Z, "clearance": 2.0, **STOCK}
MODULE_PARAMS = {"prep:1": {"tool": 1, "tool_offset": 1, "op_present": True},
                 "cutcond:1": {"spindle_rpm": 800.0, "coolant": False, "op_present": True},
                 "cutmotion:1": {"kind": "ROUGH", "feed": 160.0, "paths": [], "op_present": True}}
DIALECTS = {
    "iso": (["%", "O0001 (PROPERTY)", "G21 G18 G40 G90", "(OP 1 ROUGH T01)", "G00 X80.000 Z30.000", "T0101",
             "G97 S800 M03", "G98 F160.000"], ["G00 X80.000 Z30.000", "M05", "M30", "%"],
            {"rapid": "G00", "feed": "G01"}),
    "840d": (["%_N_PROPERTY_MPF", ";$PATH=/_N_MPF_DIR", "G18 G71 G90 G40 DIAMON", "; OP 1 ROUGH T1",
              "G0 X80.000 Z30.000", "T1 D1", "G97 S800 M3", "G94 F160"], ["G0 X80.000 Z30.000", "M5", "M30"],
             {"rapid": "G0", "feed": "G1"}),
}


def lathe(dialect: str) -> Machine:
    return Machine(f"lathe-{dialect}", "lathe", dialect, 0, 400, 0, 0, -600, 200, 4000, None, None)


def part_radius(z: float) -> float:
    return next((r for front, back, r in STEPS if back <= z <= front), 0.0)


def part_radii(z: float) -> tuple[float, float]:
    """(least, largest) radius of the part over [z - margin, z + margin]."""
    zs = [z - MARGIN_MM, z, z + MARGIN_MM, *(e for step in STEPS for e in step[:2] if abs(e - z) <= MARGIN_MM)]
    radii = [part_radius(one) for one in zs]
    return min(radii), max(radii)


def feed_radius_range(feed, z: float) -> tuple[float, float] | None:
    """(least, largest) radius of an earlier feed over [z - margin, z + margin], None if it is not there."""
    (z0, r0), (z1, r1) = feed
    low, high = max(min(z0, z1), z - MARGIN_MM), min(max(z0, z1), z + MARGIN_MM)
    if low > high:
        return None
    if z0 == z1:
        return min(r0, r1), min(r0, r1)
    at = [r0 + (r1 - r0) * (one - z0) / (z1 - z0) for one in (low, high)]
    return min(at), max(at)


def covers(feed, z: float) -> bool:
    (z0, _), (z1, _) = feed
    return min(z0, z1) <= z - MARGIN_MM and z + MARGIN_MM <= max(z0, z1)


def surely_in_part(z: float, r: float) -> bool:
    return r < part_radii(z)[0] - MARGIN_MM


def surely_off_part(z: float, r: float) -> bool:
    return r > part_radii(z)[1] + MARGIN_MM


def surely_in_material(z: float, r: float, feeds) -> bool:
    if surely_in_part(z, r):
        return True
    if not (z < BLANK_FRONT - MARGIN_MM and r < BLANK_RADIUS - MARGIN_MM):     # the bar runs on behind
        return False
    return all(found is None or found[0] > r + MARGIN_MM for found in (feed_radius_range(f, z) for f in feeds))


def surely_in_air(z: float, r: float, feeds) -> bool:
    if not surely_off_part(z, r):
        return False
    if not (z < BLANK_FRONT + MARGIN_MM and r < BLANK_RADIUS + MARGIN_MM):
        return True
    return any(covers(f, z) and feed_radius_range(f, z)[1] < r - MARGIN_MM for f in feeds)


def samples(start, end):
    count = max(1, math.ceil(math.dist(start, end) / SAMPLE_MM))
    return [(start[0] + (end[0] - start[0]) * i / count, start[1] + (end[1] - start[1]) * i / count)
            for i in range(count + 1)]


def truth(moves) -> tuple[bool, bool]:
    """(surely wrong, surely right) for the program's geometry, by sampling."""
    feeds: list = []
    wrong, right = False, True
    here = (CHANGE_Z, CHANGE_X / 2.0)
    for kind, x, z in moves:
        there = (z, x / 2.0)
        points = samples(here, there)
        if kind == "rapid":
            wrong |= any(surely_in_material(pz, pr, feeds) for pz, pr in points)
            right &= all(surely_in_air(pz, pr, feeds) for pz, pr in points)
        else:
            wrong |= any(surely_in_part(pz, pr) for pz, pr in points)
            right &= all(surely_off_part(pz, pr) for pz, pr in points)
            feeds.append((here, there))
        here = there
    return wrong, right


grid = st.integers(0, 120).map(lambda i: i * 0.5)            # X, diameter 0 … 60 mm
z_grid = st.integers(-100, 20).map(lambda i: i * 0.5)        # Z -50 … 10 mm
move = st.tuples(st.sampled_from(["rapid", "feed"]), grid, z_grid)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(dialect=st.sampled_from(sorted(DIALECTS)), moves=st.lists(move, min_size=1, max_size=6))
def test_no_program_through_material_or_into_the_part_is_accepted(dialect, moves):
    head, tail, words = DIALECTS[dialect]
    body = [f"{words[kind]} X{x:.3f} Z{z:.3f}" for kind, x, z in moves]
    lines = head + body + tail
    report = simulate_turning(lines, PARAMS, MODULE_PARAMS, lathe(dialect), "PROPERTY")
    geometry = [f for f in report.refusals if any(word in f.message for word in GEOMETRY)]
    wrong, right = truth(moves + [("rapid", CHANGE_X, CHANGE_Z)])
    if wrong:
        assert geometry, (lines, report.lines())
    if right:
        assert not geometry, (lines, report.lines())
