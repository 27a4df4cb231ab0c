"""Cutting data for a hobbing job: hob speed and feeds (reference/hobbing.md §B4–B5, §C).

Defaults come from the typical-practice table of the reference (to be calibrated with the
shop's own history); any value can be overridden per job.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import EngineError

# Cutting speed v [m/min] by material, for uncoated and coated HSS hobs, wet (§C, mid-range).
CUTTING_SPEED = {
    "45": (38.0, 90.0),
    "C45": (38.0, 90.0),
    "20CrMnTi": (35.0, 85.0),
    "40Cr": (28.0, 70.0),
}
UNKNOWN_MATERIAL_SPEED = (25.0, 50.0)   # conservative when the material is not in the table

# Axial feed per workpiece revolution f_a [mm/rev] by module (upper bound, rough, finish) (§C).
AXIAL_FEED = ((1.0, 1.5, 0.8), (2.0, 2.5, 1.2), (3.0, 3.0, 1.5), (float("inf"), 3.0, 1.5))
RADIAL_TO_AXIAL = 0.35   # radial infeed (in air) per workpiece revolution, relative to f_a


@dataclass(frozen=True)
class CuttingData:
    cutting_speed: float          # m/min
    hob_speed: int                # n0, r/min of B
    axial_feed_rough: float       # mm per workpiece revolution
    axial_feed_finish: float
    radial_feed: float            # mm per workpiece revolution (rough cut, and finish unless given)
    source: str
    radial_feed_finish: float | None = None   # mm per workpiece revolution; None = radial_feed

    @property
    def finish_radial_feed(self) -> float:
        return self.radial_feed if self.radial_feed_finish is None else self.radial_feed_finish

    def with_overrides(self, **overrides) -> "CuttingData":
        """A speed or feed of 0 or below stops the hob or the feed: refused as it is given."""
        given = {name: value for name, value in overrides.items() if value is not None}
        for name, value in given.items():
            if not value > 0:
                raise EngineError(f"{name.replace('_', ' ')} {value:g} must be above 0 (r/min or mm/min)")
        return replace(self, **given, source=self.source + " + overrides") if given else self


def hob_speed(cutting_speed: float, hob_tip_diameter: float, spindle_max: float) -> int:
    """n0 = 1000·v/(π·d_a0) to the nearest r/min, never above the machine's hob spindle limit (§B4)."""
    return min(round(1000 * cutting_speed / (math.pi * hob_tip_diameter)), math.floor(spindle_max))


def default_cutting_data(module: float, material: str | None, coated: bool,
                         hob_tip_diameter: float, spindle_max: float) -> CuttingData:
    speeds = CUTTING_SPEED.get(material or "", UNKNOWN_MATERIAL_SPEED)
    speed = speeds[1] if coated else speeds[0]
    rough, finish = next((r, f) for limit, r, f in AXIAL_FEED if module <= limit)
    known = "table" if material in CUTTING_SPEED else "unknown material, conservative"
    return CuttingData(speed, hob_speed(speed, hob_tip_diameter, spindle_max), rough, finish,
                       RADIAL_TO_AXIAL * rough, f"defaults ({known})")


def per_minute(feed_per_workpiece_rev: float, hob_speed_rpm: float, starts: int, teeth: int) -> float:
    """v_f = f_a·n2 with table speed n2 = n0·z0/z2 (§B5)."""
    return feed_per_workpiece_rev * hob_speed_rpm * starts / teeth
