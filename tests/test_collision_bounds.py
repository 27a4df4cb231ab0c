"""The collision bound along a move (engine.simulation.hobbing.contact_bounds, issue 28): a straight
move whose poses, 0.5 mm apart, straddle the hob's deepest point in the fixture. Sampled, the
hob stays outside; the true depth, worked out here from the geometry, is reported.

A level hob (A = 0: its axis along Y) of tip radius r0 35 and length L 100 at a height inside
the fixture's: its slice there is the rectangle X ∈ [cx − r0, cx + r0], Y ∈ [cy − L/2, cy + L/2]
(narrower in X at any other height: the half-width √(r0² − dz²) < r0), so with both of the
near corner's coordinates positive its nearest point to the work axis is that corner,
(cx − r0, cy − L/2). The move carries the corner along a line at distance d from the axis,
diagonally in X and Y: the corner's least distance is d, the deepest point R − d, midway
between two poses, where the samples show only R − √(d² + 0.25²)."""
from __future__ import annotations

import math

import pytest

from engine.simulation.hobbing import contact
from engine.simulation.hobbing.contact_records import COLLISION_TOLERANCE, Motion
from engine.simulation.hobbing.envelope import HobBody
from engine.simulation.hobbing.paths import move_pieces, pieces_poses
from engine.simulation.hobbing.solids import Solid

R0, HALF, FIXTURE = 35.0, 50.0, 10.0        # mm: hob tip radius, half its length; the fixture's radius
PATHS = pytest.mark.parametrize("sections", [10 ** 12, -1], ids=["plain floats", "numpy"])


def corner_move(d: float, before: float, after: float, z: float) -> tuple[dict, dict]:
    """Machine positions (A = 0: the centre is (X, Y, Z)) carrying the hob's near corner
    (X − r0, Y − L/2) along the line at distance d from the axis, direction (1, −1)/√2, from
    `before` mm ahead of its nearest point to `after` mm past it."""
    foot = d / math.sqrt(2.0)

    def at(t: float) -> dict:
        return {"X": R0 + foot + t / math.sqrt(2.0), "Y": HALF + foot - t / math.sqrt(2.0), "Z": z}

    return at(-before), at(after)


@PATHS
def test_a_move_whose_poses_straddle_the_deepest_point_reports_the_true_depth(monkeypatch, sections):
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    fixture = Solid("the fixture", -200.0, -50.0, FIXTURE)
    d, z = FIXTURE - 0.003, -100.0              # the corner 0.003 mm inside at its nearest; Z a fixture height
    start, end = corner_move(d, 10.249, 9.749, z)   # 41 poses 0.49995 mm apart, two 0.25 mm either side
    pieces = move_pieces(start, end, rapid=False)
    xs, ys, _ = pieces_poses(pieces)
    nearest = min(math.hypot(x - R0, y - HALF) for x, y in zip(xs, ys))    # the corner at each pose
    assert nearest == pytest.approx(math.hypot(d, 0.25), abs=1e-5)   # a pose 0.24995 mm short of it
    assert FIXTURE - nearest < 0                                             # the samples stay outside
    found = contact.follow([fixture], HobBody(R0, HALF), 0.0, pieces, Motion(None, False, 0, False, "G1"))
    assert [(c.solid.name, c.below_root) for c in found] == [("the fixture", False)]
    assert found[0].depth == pytest.approx(FIXTURE - d, abs=2e-6)             # 0.003 mm
    assert found[0].height == pytest.approx(z, abs=1e-4)


@PATHS
def test_the_same_move_passing_at_the_tolerance_is_accepted(monkeypatch, sections):
    """The control: the corner's least distance R − 0.0019 mm, under the tolerance: nothing."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    fixture = Solid("the fixture", -200.0, -50.0, FIXTURE)
    pieces = move_pieces(*corner_move(FIXTURE - 0.0019, 10.249, 9.749, -100.0), rapid=False)
    assert FIXTURE - 0.0019 > FIXTURE - COLLISION_TOLERANCE
    assert contact.follow([fixture], HobBody(R0, HALF), 0.0, pieces, Motion(None, False, 0, False, "G1")) == []
