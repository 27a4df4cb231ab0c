"""The hob's own geometry (docs/reference/hobbing.md §B), which choosing a hob already needs:
its lead angle and the length of it that generates a tooth. Lengths in mm, angles in degrees.
engine.hobbing.geometry builds the machining geometry on these."""
from __future__ import annotations

import math

ADDENDUM_FACTOR = 1.0     # tip = d + 2·m
DEDENDUM_FACTOR = 1.25    # root = d − 2·1.25·m
TOOTH_DEPTH_FACTOR = ADDENDUM_FACTOR + DEDENDUM_FACTOR   # h = 2.25·m


def hob_reference_diameter(hob_tip_diameter: float, module: float) -> float:
    """d_m0 ≈ d_a0 − 2·1.25·m_n (§B1)."""
    return hob_tip_diameter - 2 * DEDENDUM_FACTOR * module


def lead_angle(module: float, starts: int, hob_tip_diameter: float) -> float:
    """Hob lead angle γ: sin γ = z0·m_n/d_m0 (§B1)."""
    return math.degrees(math.asin(starts * module / hob_reference_diameter(hob_tip_diameter, module)))


def generating_length(module: float, pressure_angle: float) -> float:
    """Axial length of the hob that generates the tooth: 2·h/tan α_n + π·m_n with
    h = 2.25·m_n (§B15); the hob must be this long plus the shift and its margins."""
    depth = TOOTH_DEPTH_FACTOR * module
    return 2 * depth / math.tan(math.radians(pressure_angle)) + math.pi * module
