"""Where the hob centre lies when its tip just touches the intended root of a gear whose root
varies along Z: a taper's cone (reference §B12) or a crowned gear's parabola (§B11). A
swivelled hob's points off the Y = 0 plane lie at other heights than its centre (§B7), so the
tangency of its section in that plane is not enough: every point of the tip cylinder must stay
outside the root r(z). For one point at (x', y, z) from the centre, the centre distance X
keeps it outside when √((X + x')² + y²) ≥ r(z); the centre's X is the largest such bound over
the cylinder (sampled, then sampled again finely around the worst point). The sampling is numpy's,
imported by the first taper or crowned gear: a spur or helical gear's command never loads it (issue 28)."""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

COARSE = (121, 361)        # samples along the hob axis and around it
REFINE_SPAN = 3            # coarse steps either side of the worst sample, sampled again finely

RootRadius = Callable[["np.ndarray"], "np.ndarray"]   # intended root radius at heights z (DIN, mm)


def centre_on_root_cone(root_radius: float, cone_angle: float, hob_radius: float, hob_length: float,
                        swivel: float) -> tuple[float, float]:
    """(X of the hob centre at Z = 0 (the top face) with the tip cylinder tangent to the root
    cone, how far along Z from the centre it touches)."""
    slope = math.tan(math.radians(cone_angle))
    return contact_on_root(lambda z: root_radius + z * slope, 0.0, hob_radius, hob_length, swivel)


def centre_on_root(root: RootRadius, z_centre: float, hob_radius: float, hob_length: float,
                   swivel: float) -> float:
    """X of the hob centre at height z_centre with the tip cylinder tangent to the root r(z)."""
    return contact_on_root(root, z_centre, hob_radius, hob_length, swivel)[0]


def contact_on_root(root: RootRadius, z_centre: float, hob_radius: float, hob_length: float,
                    swivel: float) -> tuple[float, float]:
    """(X of the centre, Z of the contact point less z_centre): a swivelled hob touches the root
    off its centre's height, so a pass must carry the centre that much beyond a face."""
    import numpy as np
    eta, half = math.radians(swivel), hob_length / 2
    along, around = np.linspace(-half, half, COARSE[0]), np.linspace(0, 2 * math.pi, COARSE[1])
    coarse = _needed(root, z_centre, hob_radius, eta, along, around)
    (i, j) = coarse[2]
    d_along, d_around = along[1] - along[0], around[1] - around[0]
    fine_along = np.linspace(max(-half, along[i] - REFINE_SPAN * d_along),
                             min(half, along[i] + REFINE_SPAN * d_along), COARSE[0])
    fine_around = np.linspace(around[j] - REFINE_SPAN * d_around, around[j] + REFINE_SPAN * d_around, COARSE[1])
    fine = _needed(root, z_centre, hob_radius, eta, fine_along, fine_around)
    best = max(coarse, fine, key=lambda found: found[0])
    return best[0], best[1]


def _needed(root, z_centre, hob_radius, eta, along, around) -> tuple[float, float, tuple[int, int]]:
    import numpy as np
    t, phi = np.meshgrid(along, around, indexing="ij")
    x = hob_radius * np.cos(phi)
    y = t * math.cos(eta) - hob_radius * np.sin(phi) * math.sin(eta)
    dz = t * math.sin(eta) + hob_radius * np.sin(phi) * math.cos(eta)
    # a root continued past the work axis (a steep parabola far beyond a face) is the axis itself
    radius = np.maximum(root(z_centre + dz), 0.0)
    bound = np.sqrt(np.maximum(radius ** 2 - y ** 2, 0.0)) - x
    worst = np.unravel_index(int(np.argmax(bound)), bound.shape)
    return float(bound[worst]), float(dz[worst]), (int(worst[0]), int(worst[1]))
