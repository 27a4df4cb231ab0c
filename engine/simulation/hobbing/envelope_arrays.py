"""The hob envelope of engine.simulation.hobbing.envelope for many poses and heights at once,
with numpy: the same least distance from the work axis per height, by golden-section search
along the section's free coordinate, for every pose and height together. A batch of gears
follows hundreds of thousands of sections, about ten times faster so than one by one in plain
floats, but importing numpy takes about 0.1 s: a process follows its first sections in plain
floats (engine.simulation.hobbing.contact.MATH_SECTIONS) and imports this module only after
them, so one gear's command never loads numpy (issue 28). The two agree to about a micrometre
(tests/test_simulation_random.py)."""
from __future__ import annotations

import math

import numpy as np

from .envelope import HobBody

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
SEARCH_STEPS = 24          # the free coordinate's interval (≤ the hob length) shrinks by 1e-5


def span_radii(hob: HobBody, swivel: float, spans: list, heights: list[float]) -> list[list[float]]:
    """Per span (cx, cy, cz, first, last: a pose and the indices of `heights` it reaches), the
    least distance at each of heights[first:last], inf where the hob has no point there."""
    cx, cy, cz = (np.array([span[i] for span in spans], float)[:, None] for i in range(3))
    first, last = (np.array([span[i] for span in spans]) for i in (3, 4))
    index = np.minimum(first[:, None] + np.arange(int((last - first).max()))[None, :], len(heights) - 1)
    radius = nearest_radius(hob, swivel, cx, cy, cz, np.asarray(heights, float)[index])
    return [row[:end - start].tolist() for row, start, end in zip(radius, first, last)]


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
