"""The thickest chip a program's pass makes, as the simulation works it out from the pass's feed
and the gear and hob records (reference §C1, Hoffmeister), written from the reference and not
taken from the planner (engine.gears.chip_thickness): a slip in the planner's formula would
otherwise bound the feeds and prove them too (adversary 29). The planner solves the formula for
the feed; here h_max is evaluated at the feed the program's F word and coupling give.

    h_max = 4.9·m_n · z2^(9.25e-3·β0 − 0.542) · e^(−0.015·β0) · e^(−0.015·x) · (r_a0/m_n)^(−8.25e-3·β0 − 0.225)
            · (gashes/z0)^(−0.877) · (f_a/m_n)^0.511 · (T/m_n)^0.319

T: each toothing's whole depth, (d_a − d_f)/2 of the record and at least 2.25·m_n (§B15)."""
from __future__ import annotations

import math

ALLOWED = 0.20          # mm, the thickest chip §C1 allows an HSS hob
STANDARD_DEPTH = 2.25   # T/m_n of a standard tooth (§B15), the least depth taken
TOLERANCE = 1e-6        # relative: a feed written at the bound is at the bound


def hoffmeister(module: float, teeth: int, helix: float, shift: float, hob_tip_radius: float, edges: float,
                feed: float, depth: float) -> float:
    """h_max [mm] at axial feed `feed` [mm per workpiece revolution], `edges` = gashes per start."""
    beta = abs(helix)
    return (4.9 * module * teeth ** (0.00925 * beta - 0.542) * math.exp(-0.015 * beta) * math.exp(-0.015 * shift)
            * (hob_tip_radius / module) ** (-0.00825 * beta - 0.225) * edges ** -0.877
            * (feed / module) ** 0.511 * (depth / module) ** 0.319)


def _depth(module: float, tip, root) -> float:
    standard = STANDARD_DEPTH * module
    return standard if tip is None or root is None else max(standard, (float(tip) - float(root)) / 2)


def chip_thickness(feed: float, gear, hob) -> float:
    """The thickest h_max [mm] over the gear's toothings (unit 1 and a duplex's further units)."""
    module, helix = float(gear.module), float(gear.helix_angle or 0.0)
    shift = float(gear.profile_shift) if getattr(gear, "profile_shift", None) is not None else 0.0
    toothings = [(gear.teeth, gear.tip_diameter, gear.root_diameter)]
    toothings += [(unit.teeth, unit.tip_diameter, unit.root_diameter) for unit in gear.units]
    return max(hoffmeister(module, teeth, helix, shift, hob.tip_diameter / 2, hob.gashes / hob.starts, feed,
                           _depth(module, tip, root)) for teeth, tip, root in toothings)


def chip_problem(feed: float, gear, hob, motion: str) -> str | None:
    """The pass's chips above ALLOWED, said; None within."""
    thickness = chip_thickness(feed, gear, hob)
    if thickness <= ALLOWED * (1 + TOLERANCE):
        return None
    return (f"the {motion} feeds {feed:.3f} mm per workpiece revolution: chips of {thickness:.3f} mm by "
            f"Hoffmeister's h_max (m{gear.module:g} z{gear.teeth}, hob {hob.id}: {hob.starts} start(s), "
            f"{hob.gashes} gashes), above the {ALLOWED:g} mm allowed (reference §C1)")
