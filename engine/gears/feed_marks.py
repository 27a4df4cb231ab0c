"""Feed marks of a hobbed flank and the depth a gear's quality grade allows (reference §B6, issue 29).

Every workpiece revolution the hob moves on by the axial feed f_a; its tip circle (d_a0) leaves
a scallop between two positions, δ ≈ f_a²·sin α_n/(4·d_a0) deep on the flank [K]. The marks run
across the face width, so they are a waviness of the flank line: they count against the helix
form tolerance f_fβ of ISO 1328-1:2013, formula (11) [S, as public gear-tolerance calculators
quote it; the standard's own text was not retrieved] (DIN 3962-2 and GB/T 10095 grade the same
deviation with the same √2 step [K]; the standard's classes run 1–11, grade 12 takes the next
step). The marks may take a share of it, the rest is left for the hob's, the machine's and the
set-up's errors: that share is a rule of thumb [K], the engine's choice, to calibrate.

The engine bounds the axial feed of a job's last cut by it (engine.programs.instantiate); the
simulation (engine.simulation.hobbing.mark_facts) refuses a program whose last cut is deeper.
A job that leaves a process allowance for shaving or grinding is not bounded: that stock, tenths
of a mm, takes the marks (µm) with it, and the grade is the finished gear's.
"""
from __future__ import annotations

import math

from msgspec.structs import replace

from ..errors import EngineError
from ..notes import Note
from .hob_matching import DEFAULT_GRADE

# ISO 1328-1:2013 formula (11), helix form tolerance of class 5 [µm]:
# f_fβT = (0.07·√d + 0.45·√b + 4)·√2^(A − 5), d the reference diameter and b the face width in mm,
# A the class. (coefficient of √d, coefficient of √b, constant) of class 5, and the step between
# adjacent classes.
HELIX_FORM_CLASS_5 = (0.07, 0.45, 4.0)
CLASS_STEP = math.sqrt(2)
# The largest feed-mark depth per quality grade, as a share of that grade's f_fβT [K]: half, the
# other half left for the hob (its class chosen per grade, engine.gears.hob_matching), the machine
# and the set-up. (finest grade of the row, share); a grade finer than the first row takes the
# first, coarser than the last the last. One share for every grade until a shop calibrates it.
MARK_SHARE_BY_GRADE = ((1, 0.5), (12, 0.5))
FEED_EPSILON = 1e-9


def helix_form_tolerance(grade: int, reference_diameter: float, face_width: float) -> float:
    """f_fβT [µm] of ISO 1328-1:2013 formula (11) for the grade (class A)."""
    per_d, per_b, constant = HELIX_FORM_CLASS_5
    base = per_d * math.sqrt(reference_diameter) + per_b * math.sqrt(face_width) + constant
    return base * CLASS_STEP ** (grade - 5)


def mark_share(grade: int) -> float:
    return next((share for finest, share in MARK_SHARE_BY_GRADE if grade <= finest), MARK_SHARE_BY_GRADE[-1][1])


def allowed_depth(grade: int | None, reference_diameter: float, face_width: float) -> float:
    """The deepest feed marks [mm] the grade allows on a toothing of that diameter and width."""
    grade = grade_of(grade)
    return mark_share(grade) * helix_form_tolerance(grade, reference_diameter, face_width) / 1000


def mark_depth(axial_feed: float, pressure_angle: float, hob_tip_diameter: float) -> float:
    """δ = f_a²·sin α_n/(4·d_a0) [mm] (§B6), f_a in mm per workpiece revolution."""
    return axial_feed ** 2 * math.sin(math.radians(pressure_angle)) / (4 * hob_tip_diameter)


def feed_for_depth(depth: float, pressure_angle: float, hob_tip_diameter: float) -> float:
    """The f_a [mm per workpiece revolution] whose marks are `depth` [mm] deep (§B6 solved for f_a)."""
    return math.sqrt(4 * hob_tip_diameter * depth / math.sin(math.radians(pressure_angle)))


def reference_diameter(module: float, teeth: int, helix_angle: float) -> float:
    """d = z·m_n/cos β [mm]."""
    return teeth * module / math.cos(math.radians(helix_angle))


def toothings(gear) -> list[tuple[str, float, float]]:
    """(name, reference diameter, face width) of every toothing of the gear: unit 1 and a
    duplex gear's further units, named as the simulation names them."""
    units = [(1, gear.teeth, gear.face_width)] + [(unit.unit, unit.teeth, unit.face_width) for unit in gear.units]
    return [(f"unit {number} ({teeth} teeth)", reference_diameter(gear.module, teeth, gear.helix_angle), width)
            for number, teeth, width in units]


def gear_allowed_depth(gear) -> float:
    """The deepest marks [mm] every toothing of the gear allows (the smallest tolerance rules)."""
    return min(allowed_depth(gear.quality_grade, d, b) for _, d, b in toothings(gear))


def slant_factor(gear) -> float:
    """cos δ of a taper's cone (1 for a cylinder): its pass runs along the cone line, F along the
    slant (§B12), so its marks are f_a/cos δ apart for an axial feed f_a."""
    return math.cos(math.radians(gear.cone_angle or 0.0))


def finishing_feed_bound(gear, hob) -> float:
    """The most axial feed f_a [mm per workpiece revolution] of the last cut."""
    return feed_for_depth(gear_allowed_depth(gear), gear.pressure_angle, hob.tip_diameter) * slant_factor(gear)


LAST_CUT_FEED = {1: ("rough", "axial_feed_rough"), 2: ("finish", "axial_feed_finish")}


def bounded_for_marks(cutting, gear, hob, cut_count: int, allowance: float, given=frozenset()):
    """The cutting data with the last cut's axial feed (the rough one of a single cut, the
    finish one of two) at most finishing_feed_bound, and the `note:` line saying so. Unchanged
    where it is within, or where an allowance is left for shaving or grinding. A feed the user
    gave (`given`, the names of the overrides) above the bound is refused, not changed."""
    kind, name = LAST_CUT_FEED[cut_count]
    feed, most = getattr(cutting, name), finishing_feed_bound(gear, hob)
    if allowance > 0 or feed <= most + FEED_EPSILON:
        return cutting
    why = (f"its feed marks f_a²·sin α_n/(4·d_a0) would be "
           f"{mark_depth(feed / slant_factor(gear), gear.pressure_angle, hob.tip_diameter) * 1000:.1f} µm, above "
           f"the {gear_allowed_depth(gear) * 1000:.1f} µm grade {grade_of(gear.quality_grade)} allows "
           f"({mark_share(grade_of(gear.quality_grade)):g} of the helix form tolerance f_fβ, ISO 1328-1; "
           "reference §B6)")
    if name in given:
        raise EngineError(f"gear {gear.id}: {name.replace('_', ' ')} {feed:g} mm per workpiece rev of the last cut: "
                          f"{why}; give at most {most:.2f}, or leave an allowance for shaving or grinding")
    note = Note(f"{kind}: axial feed {feed:.2f} mm per workpiece rev of the last cut bounded to {most:.2f}: {why}",
                "feed bounded")
    return replace(cutting, **{name: most}, notes=cutting.notes + (note,))


def grade_of(quality_grade: int | None) -> int:
    """A gear that states no grade is held to DEFAULT_GRADE, as its hob is chosen for."""
    return DEFAULT_GRADE if quality_grade is None else quality_grade
