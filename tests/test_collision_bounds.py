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

import numpy as np
import pytest

from engine.simulation.hobbing import contact, envelope_arrays
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


def reference_deepest(hob: HobBody, swivel: float, start: tuple, end: tuple, z_low: float, z_high: float) -> float:
    """The least distance from the work axis (mm) of the hob's slices at heights z_low … z_high
    over the straight move start → end (machine X, Y, Z): every slice's exact nearest point
    (envelope_arrays, checked against the cylinder's definition in test_simulation_envelope) on
    a grid of the move's share and the height, then grids around the least, 3 cells either side,
    each finer, down to 1e-7 mm. Every grid point is a true value: the result is at least the
    true least (and the deepest point R minus it at most the true deepest)."""
    a = math.radians(swivel)
    ends = [np.array([x, y * math.cos(a), z + y * math.sin(a)]) for x, y, z in (start, end)]
    extent = hob.extent(swivel)
    s_low, s_high = 0.0, 1.0
    h_low = max(z_low, min(ends[0][2], ends[1][2]) - extent)
    h_high = min(z_high, max(ends[0][2], ends[1][2]) + extent)
    best, count = math.inf, (201, 1201)
    while (s_high - s_low) * math.dist(start, end) > 1e-7 or h_high - h_low > 1e-7:
        shares, heights = np.linspace(s_low, s_high, count[0]), np.linspace(h_low, h_high, count[1])
        centre = ends[0][None, :] + shares[:, None] * (ends[1] - ends[0])[None, :]
        found = envelope_arrays.nearest_radius(hob, swivel, centre[:, :1], centre[:, 1:2], centre[:, 2:],
                                               np.broadcast_to(heights, (len(shares), len(heights))))
        at = np.unravel_index(int(np.argmin(found)), found.shape)
        best = min(best, float(found[at]))
        step_s, step_h = shares[1] - shares[0], heights[1] - heights[0]
        s_low, s_high = max(s_low, shares[at[0]] - 3 * step_s), min(s_high, shares[at[0]] + 3 * step_s)
        h_low, h_high = max(h_low, heights[at[1]] - 3 * step_h), min(h_high, heights[at[1]] + 3 * step_h)
        count = (41, 41)
    return best


@pytest.mark.slow   # a random search against a fine grid: 1.4 s a set
@PATHS
def test_random_moves_past_a_fixture_report_what_a_fine_grid_finds(monkeypatch, sections):
    """Hobs (r0 10…60, L 40…200) swivelled −45°…45°, straight moves of 5…40 mm in X, Y and Z
    beside or above a fixture whose top face is at Z −50, its radius set so that the grid's
    deepest point lies between 0.003 mm outside and 0.008 mm inside: the simulation reports a
    collision exactly where the grid finds one deeper than the tolerance, at least as deep,
    and no deeper than the grid's by more than 1e-6 mm."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    rng = np.random.default_rng(28)
    verdicts = []
    for _ in range(24):
        hob = HobBody(float(rng.uniform(10, 60)), float(rng.uniform(20, 100)))
        swivel = float(rng.uniform(-45, 45))
        middle = np.array([rng.uniform(0.5, 1.5) * hob.radius + 10.0, rng.uniform(-1.2, 1.2) * hob.half_length,
                           -50.0 + rng.uniform(-1.0, 0.3) * hob.extent(swivel)])
        travel = rng.normal(size=3)
        travel *= rng.uniform(5, 40) / np.linalg.norm(travel)
        start, end = tuple(middle - travel / 2), tuple(middle + travel / 2)
        least = reference_deepest(hob, swivel, start, end, -400.0, -50.0)
        target = float(rng.uniform(-0.003, 0.008))
        fixture = Solid("the fixture", -400.0, -50.0, least + target)
        pieces = move_pieces(dict(zip("XYZ", start)), dict(zip("XYZ", end)), rapid=False)
        found = contact.follow([fixture], hob, swivel, pieces, Motion(None, False, 0, False, "G1"))
        verdicts.append((target > COLLISION_TOLERANCE, bool(found)))
        if found:
            assert target - 1e-7 <= found[0].depth <= target + 1e-6
        else:
            assert target <= COLLISION_TOLERANCE + 1e-7
    assert [want for want, _ in verdicts] == [got for _, got in verdicts]
    assert 5 <= sum(want for want, _ in verdicts) <= 20          # both verdicts tried
