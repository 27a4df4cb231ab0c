"""A cut's least distance per height (engine.simulation.hobbing.least_arrays, issue 28) against
every slice worked out: the pruning by X alone and by the bounds may leave slices out, but
never one that is the least at its height, nor one of several equally least (the first pose of
equal depths is the reported one). The reference is the exact envelope (envelope_arrays, held
to dense sampling of the cylinder in tests/test_simulation_envelope.py) on every slice of every
pose, with no bound: the same arithmetic per slice, so the two must agree to the last bit."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.simulation.hobbing.envelope import HobBody
from engine.simulation.hobbing.envelope_arrays import Sections
from engine.simulation.hobbing.least_arrays import FEW, least_sections

HEIGHT_STEP = 0.5     # mm, as a unit's heights
POSE_STEP = 0.5       # mm between poses along a move


def moves(seed: int) -> list[dict]:
    """Axial passes, radial infeeds (few poses and many), diagonal moves; level, nearly level,
    helical and steep hobs; shifts that put the hob's closest approach far off its centre."""
    rng = np.random.default_rng(seed)
    found = []
    for i in range(24):
        radius, length = rng.uniform(25, 60), rng.uniform(60, 220)
        swivel = [0.0, 1.5, -3.0, 15.0, -25.0, 35.0, -50.0][i % 7] + rng.uniform(-0.5, 0.5)
        kind = ("axial", "radial", "radial-many", "diagonal")[i % 4]
        x = rng.uniform(40, 90) + radius
        z = rng.uniform(-60, 20)
        travel = {"axial": (0.0, rng.uniform(-90, -40)), "radial": (-1.0, 0.0),
                  "radial-many": (-rng.uniform(10, 30), 0.0),
                  "diagonal": (-rng.uniform(5, 20), rng.uniform(-60, -20))}[kind]
        shift = rng.uniform(-0.8, 0.8) * length / 2
        found.append({"hob": HobBody(radius, length / 2), "swivel": swivel, "start": (x, shift, z),
                      "travel": travel, "face": (rng.uniform(-60, -20), 0.0)})
    return found


def grid(move: dict):
    """The poses (cx, cy, cz of shape (P, 1)), the unit's heights, and each pose's heights as
    contact_arrays passes them (raw from the pose's first, padded; last); None where no pose
    reaches the unit's heights."""
    hob, swivel = move["hob"], move["swivel"]
    (x, y, z), (dx, dz) = move["start"], move["travel"]
    count = max(2, int(math.ceil(math.hypot(dx, dz) / POSE_STEP)) + 1)
    share = np.arange(count) / (count - 1)
    a = math.radians(swivel)
    cx, cy, cz = x + share * dx, np.full(count, y * math.cos(a)), z + share * dz + y * math.sin(a)
    low, high = move["face"]
    heights = np.linspace(low, high, max(2, int(math.ceil((high - low) / HEIGHT_STEP)) + 1))
    extent = hob.radius * abs(math.cos(a)) + hob.half_length * abs(math.sin(a))
    first = np.searchsorted(heights, cz - extent)
    last = np.searchsorted(heights, cz + extent, side="right")
    keep = last > first
    if not keep.any():
        return None      # the move passes above or below the unit: contact_arrays follows no slice
    cx, cy, cz, first, last = cx[keep], cy[keep], cz[keep], first[keep], last[keep]
    raw = first[:, None] + np.arange(int((last - first).max()))[None, :]
    return (cx[:, None], cy[:, None], cz[:, None]), heights, raw, last


def every_slice(move: dict, poses, heights, raw, last):
    """(height index, distance) of every slice of every pose, row-major, no slice left out."""
    cx, cy, cz = poses
    valid = raw < last[:, None]
    index = np.minimum(raw, len(heights) - 1)
    distance = Sections(move["hob"], move["swivel"], cx, cz, heights[index]).nearest(cy)
    return index[valid], distance[valid]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_least_per_height_is_that_of_every_slice_and_every_equal_least_is_kept(seed):
    sizes = []
    for move in moves(seed):
        if grid(move) is None:
            continue
        poses, heights, raw, last = grid(move)
        sizes.append(raw.size)
        index, radius, least = least_sections(move["hob"], move["swivel"], poses, heights, raw, last)
        all_index, all_radius = every_slice(move, poses, heights, raw, last)
        expected = np.full(len(heights), np.inf)
        np.minimum.at(expected, all_index, all_radius)
        assert np.array_equal(least, expected), move
        for height in np.flatnonzero(np.isfinite(expected)):
            equal = np.count_nonzero((all_index == height) & (all_radius == expected[height]))
            assert np.count_nonzero((index == height) & (radius == expected[height])) == equal, (move, height)
        assert np.all(np.isinf(radius) | np.isin(radius, all_radius)), move
    assert min(sizes) <= FEW < max(sizes)      # both ways through: all bounded at once, and pruned first
