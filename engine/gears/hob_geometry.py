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


def normal_from_axial(axial_module: float, starts: int, hob_tip_diameter: float) -> float:
    """m_n = m_x·cos γ0 of a hob catalogued by the worm's axial module m_x (worm-wheel hobs, DIN
    3975), γ0 its lead angle: tan γ0 = z0·m_x/d_m0 with d_m0 = d_a0 − 2·1.25·m_n, the reference
    diameter lead_angle reads (§B1). So lead_angle(m_n, …) gives this γ0 back, and the hob's axial
    module m_n/cos γ0 is m_x (hob_axial_module). m_n enters d_m0 only through 2.5·m_n·(1 − cos γ0), so
    the iteration contracts by about 2.5·z0·m_x·sin γ0/d_m0 per step (below 0.05)."""
    module = axial_module
    for _ in range(100):
        lead = math.atan(starts * axial_module / hob_reference_diameter(hob_tip_diameter, module))
        module, previous = axial_module * math.cos(lead), module
        if abs(module - previous) <= 1e-15 * axial_module:
            break
    return module


def hob_axial_module(module: float, starts: int, hob_tip_diameter: float) -> float:
    """m_x = m_n/cos γ0: the hob's axial pitch over π, the module a worm-wheel hob is catalogued by."""
    return module / math.cos(math.radians(lead_angle(module, starts, hob_tip_diameter)))


def generating_length(module: float, pressure_angle: float) -> float:
    """Axial length of the hob that generates the tooth: 2·h/tan α_n + π·m_n with
    h = 2.25·m_n (§B15); the hob must be this long plus the shift and its margins."""
    depth = TOOTH_DEPTH_FACTOR * module
    return 2 * depth / math.tan(math.radians(pressure_angle)) + math.pi * module
