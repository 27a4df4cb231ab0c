"""The reach in Z of a hob that swivels (engine.simulation.hobbing.swivel_sweep.z_reach) against the
hob's own rim: the tip cylinder's two end circles sampled at every swivel 0.01° apart between the
two ends of the move. The reach may not be less than any sampled point's (a swivel would then
pass a solid unseen) and not more than the samples' plus what the sampling can miss."""
from __future__ import annotations

import math
import random

import numpy as np
import pytest

from engine.simulation.hobbing.envelope import HobBody
from engine.simulation.hobbing.swivel_sweep import UNKNOWN, z_reach

SAMPLE = 0.01    # degrees between the sampled swivels
RIM = 72         # points on each end circle


def rim_reach(body: HobBody, shift: float, swivels: np.ndarray) -> np.ndarray:
    """How far the hob reaches in Z from its position's Z at each swivel A (degrees): its centre at
    Z + Y·sin A (reference §A6, |Y| = shift either way), its axis (0, cos A, sin A), its end circles
    of radius r0 about that axis at ±L/2 (DIN: the swivel turns the hob about X)."""
    a = np.radians(swivels)[:, None, None]
    end = np.array([-1.0, 1.0])[None, :, None]
    t = 2 * np.pi * np.arange(RIM)[None, None, :] / RIM
    z = end * body.half_length * np.sin(a) + body.radius * np.sin(t) * np.cos(a)
    return (np.abs(shift * np.sin(a)) + np.abs(z)).max(axis=(1, 2))


def sampled(body: HobBody, shift: float, low: float, high: float) -> float:
    steps = max(1, math.ceil((high - low) / SAMPLE))
    return float(rim_reach(body, shift, np.linspace(low, high, steps + 1)).max())


def slack(body: HobBody, shift: float) -> float:
    """What a sample SAMPLE/2 from the peak, and the rim's points 5° apart, can miss (mm)."""
    return (shift + body.half_length + body.radius) * (math.radians(SAMPLE / 2) + 1 - math.cos(math.pi / RIM))


CASES = [(HobBody(35.0, 50.0), 0.0, 1.763, 80.0), (HobBody(35.0, 50.0), 20.0, -30.0, 30.0),
         (HobBody(10.0, 40.0), 5.0, 0.0, 1.0), (HobBody(50.0, 10.0), 0.0, 60.0, 89.0),
         (HobBody(35.0, 50.0), 12.0, 1.763, 181.763), (HobBody(40.0, 60.0), 0.0, 100.0, 170.0)]


@pytest.mark.parametrize("body, shift, low, high", CASES)
def test_the_reach_over_a_swivel_is_the_rims_highest_point(body, shift, low, high):
    truth = sampled(body, shift, low, high)
    reach = z_reach(body, shift, low, high)
    assert truth - 1e-9 <= reach <= truth + slack(body, shift), (reach, truth)
    assert z_reach(body, shift, high, low) == reach      # either direction of the swivel


def test_an_a_not_written_yet_may_be_any_swivel():
    body = HobBody(35.0, 50.0)
    assert z_reach(body, 7.0, None, 3.0) == pytest.approx(sampled(body, 7.0, *UNKNOWN), abs=slack(body, 7.0))
    assert z_reach(body, 7.0, None, 3.0) == pytest.approx(math.hypot(57.0, 35.0), abs=1e-12)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_random_swivels_reach_no_less_than_the_rim():
    generator = random.Random(28)
    for _ in range(40):
        body = HobBody(generator.uniform(8, 60), generator.uniform(10, 90))
        shift = generator.choice([0.0, generator.uniform(0, 40)])
        low = generator.uniform(-200, 200)
        high = low + generator.choice([generator.uniform(0, 3), generator.uniform(0, 200)])
        truth = sampled(body, shift, low, high)
        assert truth - 1e-9 <= z_reach(body, shift, low, high) <= truth + slack(body, shift), (body, shift, low, high)
