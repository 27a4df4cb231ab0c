"""The tip and root diameters of a cylindrical gear against its module, teeth, helix angle and
profile shift (reference/hobbing.md §B symbols; DIN 3960 with the basic rack of DIN 867):

    d   = m_n·z / cos β                 reference diameter
    d_a = d + 2·m_n·(h*a + x + k)       tip diameter; k ≤ 0 is the tip shortening
    d_f = d − 2·m_n·(h*f − x)           root diameter

A diameter that contradicts these is a wrong module, tooth count or helix angle (gear 42 given
module 3 with its tip diameter 42 of module 2): it is refused at the import, naming the formula,
the value it gives and the tolerance. Without a profile shift x the diameters must fit some x of
PROFILE_SHIFT_RANGE, and together they must be one tooth depth (h*a + h*f)·m_n apart.

Only the cylindrical classes (the class or an ancestor is `cylindrical`: spur, helical, duplex)
are checked. A taper gear's tip may be its large-end diameter, a crowned gear's blank is shaped,
and a worm wheel's throat diameter follows the worm (DIN 3975), not this rack: those pass as given.
"""
from __future__ import annotations

import math
from typing import Any

from ..csv_reader import Problem
from .records import normal_module

ADDENDUM = 1.0    # h*a, in modules: the basic rack's addendum (DIN 867)
DEDENDUM = 1.25   # h*f, in modules: addendum plus the tip clearance c* = 0.25 (DIN 867)
# The root a hob cuts depends on its reference profile: h*f = 1.167 (DIN 3972 profile I) up to about 1.4
# for hobs that leave grinding or shaving stock (profiles III, IV, protuberance hobs). A root inside this
# range is the hob's choice, not a contradiction.
DEDENDUM_RANGE = (1.15, 1.45)
# Drawings give the tip and root diameters to 0.1 mm at the coarsest, and d = m_n·z/cos β of a helical
# gear is irrational, so a written diameter may differ from the formula by a rounding; any wrong m_n, z or
# β moves the diameters by a module or more, far beyond this.
DIAMETER_TOLERANCE = 0.1   # mm
# Profile shifts of hobbed gears lie in about −0.5 … +1 (DIN 3992); a diameter that needs an x outside
# this wider range is not a shift but a wrong module, tooth count or helix angle.
PROFILE_SHIFT_RANGE = (-1.0, 1.5)
# Tip shortening k·m_n (DIN 3960) keeps the tip clearance of a profile-shifted pair; it takes at most a
# few tenths of a module off the tip radius.
TIP_SHORTENING_MAX = 0.3   # modules, on the radius
FIX = "check module, teeth, helix_angle and profile_shift, or correct the diameter"


def reference_diameter(gear: dict[str, Any]) -> float:
    module = float(normal_module(gear["module"], gear["module_kind"], gear["helix_angle"]))
    return module * gear["teeth"] / math.cos(math.radians(float(gear["helix_angle"])))


def tip_from_shift(gear: dict[str, Any], shift: float) -> float:
    """d_a = d + 2·m_n·(h*a + x), without tip shortening."""
    return reference_diameter(gear) + 2 * float(gear["module"]) * (ADDENDUM + shift)


def root_from_shift(gear: dict[str, Any], shift: float, dedendum: float = DEDENDUM) -> float:
    """d_f = d − 2·m_n·(h*f − x)."""
    return reference_diameter(gear) - 2 * float(gear["module"]) * (dedendum - shift)


def _given(gear: dict[str, Any]) -> str:
    shift = f", x {gear['profile_shift']}" if gear.get("profile_shift") is not None else ""
    return f"m_n {gear['module']:g}, z {gear['teeth']}, β {gear['helix_angle']:g}°{shift}"


def _outside(column: str, given: Any, low: float, high: float, formula: str, gear: dict,
             said: str | None = None) -> Problem | None:
    if low - DIAMETER_TOLERANCE <= float(given) <= high + DIAMETER_TOLERANCE:
        return None
    value = f"{low:.3f}" if math.isclose(low, high) else f"{low:.3f} … {high:.3f}"
    return Problem(None, column, f"{said or given} contradicts {formula} = {value} mm for {_given(gear)} "
                                 f"(tolerance ±{DIAMETER_TOLERANCE} mm)", FIX)


def _shifts(gear: dict[str, Any]) -> tuple[float, float, str]:
    """The profile shifts a diameter may fit: the given x, else PROFILE_SHIFT_RANGE."""
    if gear.get("profile_shift") is not None:
        return float(gear["profile_shift"]), float(gear["profile_shift"]), ""
    low, high = PROFILE_SHIFT_RANGE
    return low, high, f" with x in {low:g} … {high:g}"


def diameter_problems(gear: dict[str, Any]) -> list[Problem]:
    """Each given diameter against the formulas; both given against the tooth depth."""
    low, high, over = _shifts(gear)
    shallowest, deepest = DEDENDUM_RANGE
    dedenda = f"h*f in {shallowest:g} … {deepest:g}"
    shortening = 2 * TIP_SHORTENING_MAX * float(gear["module"])
    problems = []
    if gear["tip_diameter"] is not None:
        problems.append(_outside("tip_diameter", gear["tip_diameter"], tip_from_shift(gear, low) - shortening,
                                 tip_from_shift(gear, high), f"d_a = m_n·z/cos β + 2·m_n·(1 + x + k){over}, "
                                 f"k ≥ −{TIP_SHORTENING_MAX:g}", gear))
    if gear["root_diameter"] is not None:
        problems.append(_outside("root_diameter", gear["root_diameter"], root_from_shift(gear, low, deepest),
                                 root_from_shift(gear, high, shallowest),
                                 f"d_f = m_n·z/cos β − 2·m_n·(h*f − x){over}, {dedenda}", gear))
    if not any(problems) and None not in (gear["tip_diameter"], gear["root_diameter"]) and over:
        module = 2 * float(gear["module"])
        difference = gear["tip_diameter"] - gear["root_diameter"]
        problems.append(_outside("root_diameter", difference, (ADDENDUM + shallowest) * module - shortening,
                                 (ADDENDUM + deepest) * module,
                                 f"the tooth depth: tip_diameter − root_diameter = 2·m_n·(1 + h*f + k), {dedenda}",
                                 gear,
                                 said=f"{gear['root_diameter']} (tip_diameter − root_diameter = {difference})"))
    return [problem for problem in problems if problem]
