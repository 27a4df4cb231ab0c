"""What the hob may meet, as solids of revolution about the work axis in the DIN frame: each
toothed unit of the gear (its blank: the tip radius over its face width; a taper's cone), the
fixture below the lowest unit and the tailstock above the top face (machine record, design
notes §7). A unit also knows its intended root (reference §B3, §B11, §B12; a worm wheel's
throat is the hob's own tip circle about the mid-plane, §B10) and keeps, per height, how close
to the axis the hob has cut so far (`reach`), over the whole program and within the present
coupling (`session_reach`): the gaps a coupled hob has cut are free to it while the coupling
lasts, not after a new EGON, whose phase is not the old one. Per height as plain lists of floats
(issue 28: the simulation starts without numpy)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import WorkHolding

if TYPE_CHECKING:
    from collections.abc import Callable

HEIGHT_STEP = 0.5       # mm between the heights a solid is followed at (its faces included). The
                        # clearance is convex in height but may bend sharply (near the end face's
                        # rim far more than the tip circle's 1/r0): no step allowance bounds what
                        # lies between two heights; contact_bounds bounds it by convexity instead
BEYOND_TRAVEL = 50.0    # mm: a fixture or tailstock is followed this far past the Z travel and the hob


# A dataclass, not a msgspec.Struct like the engine's other records (docs/design.md): its
# init=False fields are computed in __post_init__, which a Struct would run again when pickled.
@dataclass(eq=False)
class Solid:
    """A solid of revolution about the work axis (a gear unit, the fixture, the tailstock) between two heights."""
    name: str
    z_low: float
    z_high: float
    radius_at_top: float          # radius at z_high … (for a cone: at Z = 0, see slope)
    slope: float = 0.0            # dR/dz (a taper's tan δ)
    teeth: int | None = None      # a toothed unit: the teeth the coupling must generate to cut it
    clamped_only: bool = False    # the tailstock: there only between M20 and M21
    root: Callable[[float], float] | None = None   # height -> intended root radius (units), mm
    heights: list[float] = field(init=False)       # ascending, HEIGHT_STEP apart at most, both faces
    radius: list[float] = field(init=False)
    reach: list[float] = field(init=False)
    session_reach: list[float] = field(init=False)
    intended_root: list[float] | None = field(init=False)
    session: int = -1
    cut_sessions: set = field(default_factory=set)   # the couplings whose cuts entered its material
    height_array: Any = None      # heights and radius as numpy arrays, for a batch's sections (contact_arrays)
    radius_array: Any = None

    def __post_init__(self):
        self.heights = heights_between(self.z_low, self.z_high)
        count = len(self.heights)
        top, slope = self.radius_at_top, self.slope
        self.radius = [top + slope * height for height in self.heights] if slope else [top] * count
        self._largest = max(self.radius)
        self.reach = [math.inf] * count
        self.session_reach = [math.inf] * count
        root = self.root
        self.intended_root = [root(height) for height in self.heights] if root is not None else None

    def radius_at(self, height: float) -> float:
        return self.radius_at_top + self.slope * height

    @property
    def largest_radius(self) -> float:
        return self._largest

    def start_session(self, session: int) -> None:
        if self.session != session:
            self.session = session
            self.session_reach = [math.inf] * len(self.heights)

    def stock(self) -> list[float]:
        """How far above its intended root the hob has left each height of the unit (mm; inf
        where it never reached)."""
        assert self.intended_root is not None   # a unit, not the fixture or the tailstock
        return [reach - root for reach, root in zip(self.reach, self.intended_root)]


@lru_cache(maxsize=256)
def heights_between(z_low: float, z_high: float) -> list[float]:
    """The heights a solid from z_low to z_high is followed at: both faces, HEIGHT_STEP apart at
    most. Remembered: a batch's fixtures and tailstocks (thousands of heights each) recur from
    gear to gear; the list is shared, never changed."""
    count = max(2, int(math.ceil((z_high - z_low) / HEIGHT_STEP)) + 1)
    step = (z_high - z_low) / (count - 1)
    return [z_low + i * step for i in range(count - 1)] + [z_high]


def unit_solids(gear: Gear, hob: Hob, worm_wheel: bool) -> list[Solid]:
    """Unit 1 (the gear row, top face Z = 0) and the further units of a duplex gear."""
    units = [(1, gear.teeth, gear.face_width, gear.tip_diameter, gear.root_diameter, 0.0)]
    units += [(unit.unit, unit.teeth, unit.face_width, unit.tip_diameter, unit.root_diameter, unit.z_top)
              for unit in gear.units]
    return [_unit(gear, hob, worm_wheel, *unit) for unit in units]


def _unit(gear: Gear, hob: Hob, worm_wheel: bool, number, teeth, width, tip, root, top) -> Solid:
    slope = math.tan(math.radians(gear.cone_angle or 0.0)) if number == 1 else 0.0
    root_of = ROOTS[_shape(gear, worm_wheel, number)](gear, hob, root / 2, top, width, slope)
    return Solid(f"unit {number} ({teeth} teeth)", top - width, top, tip / 2 + 0.0, slope, teeth, root=root_of)


def _shape(gear: Gear, worm_wheel: bool, number: int) -> str:
    if worm_wheel:
        return "throat"
    if number == 1 and gear.crowning:
        return "crowned"
    return "cone"


def _cone(gear, hob, root_radius, top, width, slope):
    """Cylindrical and taper gears: d_f2/2 + z·tan δ (Z = 0 at the top face)."""
    return lambda z: root_radius + slope * z


def _crowned(gear, hob, root_radius, top, width, slope):
    """Crowning (§B11): d_f2/2 − Δa·(2(z − z_m)/b)², Δa = C_β/sin α_n, deepest at the faces."""
    depth = gear.crowning / math.sin(math.radians(gear.pressure_angle))
    middle = top - width / 2
    return lambda z: root_radius - depth * (2 * (z - middle) / width) ** 2


def _throat(gear, hob, root_radius, top, width, slope):
    """A worm wheel's root is the throat the hob's tip circle leaves about the mid-plane (§B10):
    (d_f2 + d_a0)/2 − √(r0² − (z − z_m)²)."""
    r0, middle = hob.tip_diameter / 2, top - width / 2
    centre = root_radius + r0
    return lambda z: centre - math.sqrt(max(r0 ** 2 - (z - middle) ** 2, 0.0))


ROOTS = {"cone": _cone, "crowned": _crowned, "throat": _throat}


def setup_solids(machine: Machine, units: list[Solid], hob: Hob, holding: WorkHolding | None = None) -> list[Solid]:
    """The fixture below the lowest unit's bottom face and the tailstock above the top face,
    each followed from its face to past the travel (a diameter of 0: none). A job's work-holding
    (issue 29) puts its own part under the gear, `height` mm tall, on the machine's fixture, and its
    centre in place of the machine's tailstock."""
    reach = hob.tip_diameter / 2 + hob.length
    bottom = min(unit.z_low for unit in units) - machine.fixture_gap
    top = max(unit.z_high for unit in units) + machine.tailstock_gap
    z_far_low = min(machine.z_min, -machine.z_max) - reach - BEYOND_TRAVEL
    z_far_high = max(machine.z_max, -machine.z_min) + reach + BEYOND_TRAVEL
    solids = []
    if holding is not None:
        solids.append(Solid(f"the {holding.kind} {holding.id}", bottom - holding.height, bottom, holding.diameter / 2))
        bottom -= holding.height
    if machine.fixture_diameter > 0:
        solids.append(Solid("the fixture", min(z_far_low, bottom - 1.0), bottom, machine.fixture_diameter / 2))
    tailstock = machine.tailstock_diameter if holding is None else holding.tailstock_diameter
    if tailstock > 0:
        solids.append(Solid("the tailstock", top, max(z_far_high, top + 1.0), tailstock / 2, clamped_only=True))
    return solids
