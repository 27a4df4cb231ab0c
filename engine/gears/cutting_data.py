"""Cutting data for a hobbing job: hob speed and feeds (docs/reference/hobbing.md §B4–B5, §C).

Defaults come from the typical-practice table of the reference (to be calibrated with the
shop's own history); any value can be overridden per job.
"""
from __future__ import annotations

import math

import msgspec
from msgspec.structs import replace

from ..errors import EngineError
from .chip_thickness import ALLOWED_CHIP_THICKNESS, chip_feed_bound
from .records import CuttingSpeeds
from .speed_table import SPEEDS

# Cutting speed v [m/min] by material, for uncoated and coated HSS hobs, wet (§C, mid-range): the
# seed rows' defaults (a gear loaded from the database brings its material's, table material).
CUTTING_SPEED = {name: row.defaults for name, row in SPEEDS.items()}
UNKNOWN_MATERIAL_SPEED = (25.0, 50.0)   # conservative when no material is stated

# Axial feed per workpiece revolution f_a [mm/rev] by module (upper bound, rough, finish) (§C).
AXIAL_FEED = ((1.0, 1.5, 0.8), (2.0, 2.5, 1.2), (3.0, 3.0, 1.5), (float("inf"), 3.0, 1.5))
RADIAL_TO_AXIAL = 0.35   # radial infeed (in air) per workpiece revolution, relative to f_a

# The most axial feed f_a [mm per workpiece revolution] a cut may take, by module: the upper end
# of the typical ranges of docs/reference/hobbing.md §C (single-start hob, steel, wet; typical practice
# [K], calibrate with the shop's history). (module, roughing maximum, finishing maximum), modules
# ascending; between two rows interpolated linearly, below the first and above the last row the
# end row holds. A single cut is a rough cut. Cases carry feeds from other modules (the paper's
# 8.11 mm/rev at m2, §D), so every transferred feed is bounded by this table.
FEED_MAXIMUM = ((1.0, 2.0, 1.0), (2.0, 3.0, 1.5), (3.0, 3.5, 2.0), (4.0, 4.0, 2.0))
FEED_MAXIMUM_COLUMN = {"rough": 1, "finish": 2}
# Multi-start hobs: "lower f_a to keep chip thickness in range" (§C). A cylindrical gear's feed is
# bounded by the chip thickness of Hoffmeister's formula (engine.gears.chip_thickness, §C1), for
# single- and multi-start hobs alike. A worm wheel is cut by radial or tangential feed, outside that
# formula's validity: its bound stays the single-start one / √z0, an exponent of our choice [K][?].
MULTI_START_EXPONENT = 0.5


class CuttingData(msgspec.Struct, frozen=True):
    """Speeds and feeds of a job: the case base's suggestion, bounded, with the overrides given."""
    cutting_speed: float          # m/min
    hob_speed: int                # n0, r/min of B
    axial_feed_rough: float       # mm per workpiece revolution
    axial_feed_finish: float
    radial_feed: float            # mm per workpiece revolution (rough cut, and finish unless given)
    source: str
    radial_feed_finish: float | None = None   # mm per workpiece revolution; None = radial_feed
    notes: tuple = ()             # what was bounded, one line each (engine suggest and instantiate say them)

    @property
    def finish_radial_feed(self) -> float:
        return self.radial_feed if self.radial_feed_finish is None else self.radial_feed_finish

    def of_cuts(self, cut_kinds) -> CuttingData:
        """The same data with only the notes of these cut kinds (a single-cut job has no finish)."""
        return replace(self, notes=tuple(note for note in self.notes if note.split(":")[0] in cut_kinds))

    def with_overrides(self, gear=None, hob=None, **overrides) -> CuttingData:
        """A speed or feed of 0 or below stops the hob or the feed: refused as it is given. An
        axial feed (mm per workpiece revolution) above the maximum for the gear and hob is refused
        too (feed_limit): the table's maximum is already the upper end of practice, and the chip
        bound is the hob's; a shop that proved more calibrates them, it does not pass one job
        beyond them unnoticed. An axial feed is given with the gear and hob it is for."""
        given = {name: value for name, value in overrides.items() if value is not None}
        for name, value in given.items():
            if not value > 0:
                raise EngineError(f"{name.replace('_', ' ')} {value:g} must be above 0 (r/min or mm/min)")
        for name, cut in (("axial_feed_rough", "rough"), ("axial_feed_finish", "finish")):
            if name in given:
                most, why = feed_limit(gear, hob, cut)
                if given[name] > most + FEED_EPSILON:
                    raise EngineError(f"{name.replace('_', ' ')} {given[name]:g} mm per workpiece rev exceeds "
                                      f"the {most:.2f} mm/rev {why}; give a feed within it")
        return replace(self, **given, source=self.source + " + overrides") if given else self


FEED_EPSILON = 1e-9


def table_maximum(module: float, cut: str) -> float:
    """The most f_a [mm per workpiece revolution] of the §C table for the module and cut kind
    (FEED_MAXIMUM, interpolated): a single-start hob in steel."""
    column = FEED_MAXIMUM_COLUMN[cut]
    return _interpolated([(row[0], row[column]) for row in FEED_MAXIMUM], module)


def feed_limit(gear, hob, cut: str) -> tuple[float, str]:
    """(the most f_a [mm per workpiece revolution], what it is, read after "the <f> mm/rev"): the
    §C table's maximum for the module, and for a cylindrical gear at most the feed whose chips stay
    within the allowed thickness (Hoffmeister, §C1); a worm-wheel hob's is the table's / √z0
    (radial or tangential feed, outside the formula's validity)."""
    table = table_maximum(gear.module, cut)
    if hob.purpose == "worm_wheel":
        return (table / max(1, hob.starts) ** MULTI_START_EXPONENT,
                f"{cut}ing maximum for m{gear.module:g} with a {hob.starts}-start worm-wheel hob (reference §C)")
    chip = chip_feed_bound(gear, hob)
    if chip < table:
        return chip, (f"chip-thickness bound for m{gear.module:g} z{gear.teeth} with hob {hob.id} ({hob.starts} "
                      f"start(s), {hob.gashes} gashes): Hoffmeister's h_max within {ALLOWED_CHIP_THICKNESS:g} mm "
                      "(reference §C1)")
    return table, f"{cut}ing maximum for m{gear.module:g} (reference §C)"


def _interpolated(rows: list[tuple[float, float]], x: float) -> float:
    if x <= rows[0][0]:
        return rows[0][1]
    for (x0, y0), (x1, y1) in zip(rows, rows[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return rows[-1][1]


def hob_speed(cutting_speed: float, hob_tip_diameter: float, spindle_max: float) -> int:
    """n0 = 1000·v/(π·d_a0) to the nearest r/min, never above the machine's hob spindle limit (§B4)."""
    return min(round(1000 * cutting_speed / (math.pi * hob_tip_diameter)), math.floor(spindle_max))


def default_cutting_data(module: float, material: str | None, coated: bool,
                         hob_tip_diameter: float, spindle_max: float,
                         row: CuttingSpeeds | None = None) -> CuttingData:
    """Speeds and feeds of a job with no machining history: v of the material's row (`row`, from
    table material; else the seed row of `material`) for an uncoated or coated hob [m/min]."""
    known_speeds = row.defaults if row is not None else CUTTING_SPEED.get(material or "")
    speeds = known_speeds or UNKNOWN_MATERIAL_SPEED
    speed = speeds[1] if coated else speeds[0]
    rough, finish = next((r, f) for limit, r, f in AXIAL_FEED if module <= limit)
    known = "table" if known_speeds else "unknown material, conservative"
    return CuttingData(speed, hob_speed(speed, hob_tip_diameter, spindle_max), rough, finish,
                       RADIAL_TO_AXIAL * rough, f"defaults ({known})")


def programmed_feed(mm_per_minute: float) -> float:
    """The F word written, 0.1 mm/min below or at the feed: rounding half up could carry a feed
    bounded to the §C maximum just past it (5.275 → 5.3 mm/min is 2.51 mm/rev against 2.50).
    A feed below 0.1 mm/min would be written F0 (issue 26: a gear of 5,000 teeth turns its
    table at n0·z0/z2 ≈ 0.05 r/min, §B5): refused, a program cannot cut at feed 0."""
    feed = math.floor(mm_per_minute * 10 + 1e-9) / 10
    if not feed > 0:
        raise EngineError(f"the feed works out at {mm_per_minute:.3g} mm/min, below the 0.1 mm/min an F word "
                          "can say (table speed n0·z0/z2, reference §B5): check the gear's teeth and the "
                          "hob's starts and speed")
    return feed


def per_minute(feed_per_workpiece_rev: float, hob_speed_rpm: float, starts: int, teeth: int) -> float:
    """v_f = f_a·n2 with table speed n2 = n0·z0/z2 (§B5)."""
    return feed_per_workpiece_rev * hob_speed_rpm * starts / teeth
