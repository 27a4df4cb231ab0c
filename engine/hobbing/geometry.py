"""Hobbing geometry (docs/reference/hobbing.md §B). Lengths in mm, angles in degrees. The signed
quantities (swivel, coupling factors) are engine.hobbing.conventions."""
from __future__ import annotations

import math

# The hob's own geometry is below, in engine.gears (hob matching needs it); the models read it here too.
from ..gears.hob_geometry import generating_length, hob_reference_diameter, lead_angle  # noqa: F401


def reference_diameter(module: float, teeth: int, helix_angle: float = 0.0) -> float:
    return module * teeth / math.cos(math.radians(helix_angle))


def full_depth_centre_distance(root_diameter: float, hob_tip_diameter: float) -> float:
    """a = (d_f2 + d_a0)/2 (§B3)."""
    return (root_diameter + hob_tip_diameter) / 2


def cut_depth(tip_diameter: float, hob_tip_diameter: float, centre_distance: float) -> float:
    """Radial depth h of a cut at this centre distance, from the gear tip."""
    return (tip_diameter + hob_tip_diameter) / 2 - centre_distance


def approach_length(depth: float, hob_tip_diameter: float, tip_diameter: float, swivel: float) -> float:
    """Run-in E from the face to where the hob at this depth first touches (§B7):
    spur √(h·(d_a0 − h)); with a swivel η the conservative bound
    √(h·(d_a0 − h))/cos η + tan η·√(h·(d_a2 − h))."""
    eta = math.radians(abs(swivel))
    spur = math.sqrt(depth * (hob_tip_diameter - depth))
    if eta == 0:
        return spur
    return spur / math.cos(eta) + math.tan(eta) * math.sqrt(depth * (tip_diameter - depth))


def overrun_length(module: float, depth: float, pressure_angle: float, swivel: float) -> float:
    """Run-out U beyond the far face: about 1–2·m_n, plus the axial projection of the
    generating zone (h/tan α_n)·sin η for a swivelled hob (§B8)."""
    base = max(2.0, 1.5 * module)
    extra = depth / math.tan(math.radians(pressure_angle)) * math.sin(math.radians(abs(swivel)))
    return base + extra
