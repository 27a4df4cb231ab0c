"""Where the hob centre lies when its tip just touches a taper gear's root cone (reference §B12).
A swivelled hob's points off the Y = 0 plane lie at other heights than its centre (§B7), so the
tangency of its section in that plane is not enough: every point of the tip cylinder must stay
outside the cone r(z) = r_f + z·tan δ. For one point at (x', y, z) from the centre, the centre
distance X keeps it outside when √((X + x')² + y²) ≥ r_f + z·tan δ; the centre's X is the
largest such bound over the cylinder (sampled, then refined around the worst point)."""
from __future__ import annotations

import math

import numpy as np

COARSE = (241, 721)        # samples along the hob axis and around it
REFINE_SPAN = 3            # coarse steps either side of the worst sample, sampled again finely


def centre_on_root_cone(root_radius: float, cone_angle: float, hob_radius: float, hob_length: float,
                        swivel: float) -> float:
    """X of the hob centre at Z = 0 (the top face) with the tip cylinder tangent to the root cone."""
    slope, eta = math.tan(math.radians(cone_angle)), math.radians(swivel)
    half = hob_length / 2
    along, around = np.linspace(-half, half, COARSE[0]), np.linspace(0, 2 * math.pi, COARSE[1])
    needed, (i, j) = _needed(root_radius, slope, hob_radius, eta, along, around)
    d_along, d_around = along[1] - along[0], around[1] - around[0]
    fine_along = np.linspace(max(-half, along[i] - REFINE_SPAN * d_along),
                             min(half, along[i] + REFINE_SPAN * d_along), COARSE[0])
    fine_around = np.linspace(around[j] - REFINE_SPAN * d_around, around[j] + REFINE_SPAN * d_around, COARSE[1])
    return max(needed, _needed(root_radius, slope, hob_radius, eta, fine_along, fine_around)[0])


def _needed(root_radius, slope, hob_radius, eta, along, around) -> tuple[float, tuple[int, int]]:
    t, phi = np.meshgrid(along, around, indexing="ij")
    x = hob_radius * np.cos(phi)
    y = t * math.cos(eta) - hob_radius * np.sin(phi) * math.sin(eta)
    z = t * math.sin(eta) + hob_radius * np.sin(phi) * math.cos(eta)
    cone = root_radius + z * slope
    bound = np.sqrt(np.maximum(cone ** 2 - y ** 2, 0.0)) - x
    worst = np.unravel_index(int(np.argmax(bound)), bound.shape)
    return float(bound[worst]), (int(worst[0]), int(worst[1]))
