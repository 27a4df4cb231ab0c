"""Chip thickness as the reference gives it (docs/reference/hobbing.md §C1), computed here from the
reference's text and never from the engine: Hoffmeister's maximum chip thickness

    h_max = 4.9·m_n · z2^(9.25e-3·β0 − 0.542) · e^(−0.015·β0) · e^(−0.015·x) · (r_a0/m_n)^(−8.25e-3·β0 − 0.225)
            · i^(−0.877) · (f_a/m_n)^0.511 · (T/m_n)^0.319,   i = gashes/z0,

with T the whole tooth depth 2.25·m_n, and the allowed h_max of 0.20 mm (§C1 [K]). The feed at the
bound is found by bisection on h_max(f_a), not by the engine's closed form."""
from __future__ import annotations

import math

ALLOWED = 0.20          # mm, §C1
DEPTH_IN_MODULES = 2.25  # T/m_n, §C1 (the whole tooth depth, §B15)


def h_max(module: float, teeth: int, helix: float, shift: float, hob_tip_diameter: float, gashes: int, starts: int,
          feed: float) -> float:
    """h_max [mm] for f_a `feed` [mm per workpiece revolution], term by term as §C1 writes it."""
    beta = abs(helix)
    terms = [4.9 * module,
             teeth ** (0.00925 * beta - 0.542),
             math.exp(-0.015 * beta),
             math.exp(-0.015 * shift),
             (hob_tip_diameter / 2 / module) ** (-0.00825 * beta - 0.225),
             (gashes / starts) ** -0.877,
             (feed / module) ** 0.511,
             DEPTH_IN_MODULES ** 0.319]
    return math.prod(terms)


def feed_at_bound(module: float, teeth: int, helix: float, shift: float, hob_tip_diameter: float, gashes: int,
                  starts: int) -> float:
    """The f_a [mm per workpiece revolution] at which h_max is ALLOWED (bisection; h_max rises with f_a)."""
    low, high = 0.0, 100.0
    for _ in range(200):
        middle = (low + high) / 2
        if h_max(module, teeth, helix, shift, hob_tip_diameter, gashes, starts, middle) > ALLOWED:
            high = middle
        else:
            low = middle
    return low
