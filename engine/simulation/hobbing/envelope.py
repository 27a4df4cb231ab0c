"""The hob as the simulation sees it: its tip cylinder (radius d_a0/2, length L, end faces
included), the axis in the Y–Z plane swivelled by A about X (reference §A6, §B7). Every hob
point lies within that solid, so what the cylinder does not touch, the hob does not touch.

The blank, its units, the fixture and the tailstock are all solids of revolution about the
work axis, so a hob pose meets them where, at some height z, the hob comes closer to the work
axis than the solid's radius. `nearest_radius` gives that closest distance per height: the
horizontal slice of the (convex) cylinder is convex and the distance from the work axis is a
convex function, so along the slice's one free coordinate the minimum is found by golden-section
search, for every pose and height at once (numpy). Exact to about a micrometre, not sampled.

The shift axis Y rides on the swivel head: Y moves the hob along its own axis, so the
generating zone stays where X and Z put it and a different part of the hob reaches it."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
SEARCH_STEPS = 24          # the free coordinate's interval (≤ the hob length) shrinks by 1e-5


@dataclass(frozen=True, slots=True)
class HobBody:
    radius: float          # d_a0/2
    half_length: float     # L/2

    def extent(self, swivel: float) -> float:
        """How far above and below its centre the swivelled cylinder reaches along Z."""
        a = math.radians(swivel)
        return self.radius * abs(math.cos(a)) + self.half_length * abs(math.sin(a))


def centres(x, y, z, swivel: float):
    """The hob centre in DIN coordinates for machine positions X, Y (along the hob axis), Z."""
    a = math.radians(swivel)
    return x, y * math.cos(a), z + y * math.sin(a)


def nearest_radius(hob: HobBody, swivel: float, cx, cy, cz, heights):
    """Per pose (cx, cy, cz: arrays of shape (P, 1)) and height (shape (P, W)): the least
    distance from the work axis of the hob's points at that height, inf where it has none."""
    a = math.radians(swivel)
    s, c = math.sin(a), math.cos(a)
    dz = heights - cz
    low = (-hob.half_length - s * dz) / c
    high = (hob.half_length - s * dz) / c
    if abs(s) > 1e-12:
        first, second = (c * dz - hob.radius) / s, (c * dz + hob.radius) / s
        low = np.maximum(low, np.minimum(first, second))
        high = np.minimum(high, np.maximum(first, second))
        empty = low > high
    else:
        empty = np.abs(dz) > hob.radius
    high = np.where(empty, low, high)

    def squared(dy):
        q = s * dy - c * dz
        half = np.sqrt(np.maximum(hob.radius ** 2 - q * q, 0.0))
        return np.maximum(cx - half, 0.0) ** 2 + (cy + dy) ** 2

    best = _golden_minimum(squared, low, high)
    return np.where(empty, np.inf, np.sqrt(best))


def _golden_minimum(function, low, high):
    """min of a convex function on [low, high], elementwise: one new evaluation per step, and
    both ends checked."""
    left, right = high - GOLDEN * (high - low), low + GOLDEN * (high - low)
    f_left, f_right = function(left), function(right)
    for _ in range(SEARCH_STEPS):
        keep_left = f_left < f_right
        low, high = np.where(keep_left, low, left), np.where(keep_left, right, high)
        probe = np.where(keep_left, high - GOLDEN * (high - low), low + GOLDEN * (high - low))
        f_probe = function(probe)
        left, right, f_left, f_right = (np.where(keep_left, probe, right), np.where(keep_left, left, probe),
                                        np.where(keep_left, f_probe, f_right), np.where(keep_left, f_left, f_probe))
    return np.minimum(np.minimum(f_left, f_right), np.minimum(function(low), function(high)))
