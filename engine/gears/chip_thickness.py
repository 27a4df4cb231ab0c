"""The largest chip a hob tooth cuts, and the axial feed that keeps it within a bound (docs/reference/hobbing.md §C1).

Hoffmeister's empirical formula (WZL Aachen, 1970; as given by Bouzakis et al., CIRP Annals 57
(2008) 676–696, and by Klocke/Brecher, *Zahnrad- und Getriebetechnik*) for the maximum undeformed
chip thickness of axial hobbing of a cylindrical gear [K: the formula as those sources are widely
quoted; their text was not retrieved here]:

    h_max = 4.9·m_n · z2^(9.25e-3·β − 0.542) · e^(−0.015·β) · e^(−0.015·x) · (r_a0/m_n)^(−8.25e-3·β − 0.225)
            · i^(−0.877) · (f_a/m_n)^0.511 · (T/m_n)^0.319,   i = gashes/starts

It is a power law in f_a, so the feed at a given h_max is f_a = f_ref·(h/h_ref)^(1/0.511). A
multi-start hob spreads one workpiece revolution's feed over fewer gash passes per gap (i falls by
z0), which is why its chips thicken: this replaces the engine's former ÷√z0 rule.
"""
from __future__ import annotations

import math

import msgspec

# The thickest chip an HSS hob should cut in steel [mm]: 0.20–0.25 mm is the range commonly
# given for HSS hobs (Klocke/Brecher; hob makers' guides) [K]; the engine takes the lower end,
# one value for every hob until a shop calibrates it (carbide hobs are usually run thinner [K][?]).
ALLOWED_CHIP_THICKNESS = 0.20
FEED_EXPONENT = 0.511          # of f_a/m_n in Hoffmeister's formula
TOOTH_DEPTH = 2.25             # T = 2.25·m_n: the standard whole tooth depth (§B15), the least T taken


class ChipCase(msgspec.Struct, frozen=True):
    """What Hoffmeister's formula reads of a gear, a hob and a cut."""
    module: float             # m_n [mm]
    teeth: int                # z2
    helix_angle: float        # β [degrees], its size (the formula's β0 ≥ 0)
    profile_shift: float      # x [modules]
    hob_tip_radius: float     # r_a0 = d_a0/2 [mm]
    gashes: int               # gashes (flutes) of the hob
    starts: int               # z0
    depth: float              # T [mm], the depth of cut


def max_chip_thickness(case: ChipCase, axial_feed: float) -> float:
    """h_max [mm] for an axial feed f_a [mm per workpiece revolution] (Hoffmeister)."""
    m, beta = case.module, abs(case.helix_angle)
    i = case.gashes / case.starts
    return (4.9 * m * case.teeth ** (9.25e-3 * beta - 0.542) * math.exp(-0.015 * beta)
            * math.exp(-0.015 * case.profile_shift) * (case.hob_tip_radius / m) ** (-8.25e-3 * beta - 0.225)
            * i ** -0.877 * (axial_feed / m) ** FEED_EXPONENT * (case.depth / m) ** 0.319)


def feed_for_chip_thickness(case: ChipCase, thickness: float = ALLOWED_CHIP_THICKNESS) -> float:
    """The f_a [mm per workpiece revolution] at which h_max is `thickness` [mm]: the formula
    solved for f_a (h_max ∝ f_a^0.511)."""
    at_one_module = max_chip_thickness(case, case.module)
    return case.module * (thickness / at_one_module) ** (1 / FEED_EXPONENT)


def chip_cases(gear, hob) -> list[ChipCase]:
    """One case per toothing of the gear (unit 1 and a duplex's further units), each at its whole
    tooth depth: h_max grows with T, so a feed within the bound there is within it for every pass,
    however deep. The depth is the record's (d_a − d_f)/2 where deeper than 2.25·m_n: a gear
    ground after hobbing (dedendum 1.4·m_n, ISO 53 profile D) is cut 2.4·m_n deep (adversary 29)."""
    toothings = [(gear.teeth, gear.tip_diameter, gear.root_diameter)]
    toothings += [(unit.teeth, unit.tip_diameter, unit.root_diameter) for unit in gear.units]
    shift = float(gear.profile_shift) if getattr(gear, "profile_shift", None) is not None else 0.0
    return [ChipCase(gear.module, z2, gear.helix_angle, shift, hob.tip_diameter / 2, hob.gashes, hob.starts,
                     tooth_depth(gear.module, tip, root)) for z2, tip, root in toothings]


def tooth_depth(module: float, tip_diameter, root_diameter) -> float:
    """T [mm]: (d_a − d_f)/2 of the record, at least the standard 2.25·m_n (also when not given)."""
    standard = TOOTH_DEPTH * module
    if tip_diameter is None or root_diameter is None:
        return standard
    return max(standard, (float(tip_diameter) - float(root_diameter)) / 2)


def chip_feed_bound(gear, hob) -> float:
    """The most f_a [mm per workpiece revolution] keeping every toothing's h_max within
    ALLOWED_CHIP_THICKNESS."""
    return min(feed_for_chip_thickness(case) for case in chip_cases(gear, hob))


def gear_chip_thickness(gear, hob, axial_feed: float) -> float:
    """The largest h_max [mm] over the gear's toothings at that feed."""
    return max(max_chip_thickness(case, axial_feed) for case in chip_cases(gear, hob))
