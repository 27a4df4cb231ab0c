"""Choosing a job's work-holding (issue 29), the rule a skilled setter uses: the machine record's
own fixture and tailstock when they clear the gear's root; else the largest work-holding of the
library that fits the machine, clears the root below and above the gear, and stands the machine's
fixture far enough below the gear that the hob does not reach it. As `hobs match`
(engine.gears.hob_matching), each required property is a row of HOLDING_TESTS; the library is
narrowed row by row, so a refusal names the first property that no remaining work-holding has.
The gear record has no bore: the part under the gear is held to the root alone. These are the
setter's rules before the cut; the simulation proves the program against the chosen solids."""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError, InputError
from ..machines.records import Machine, hobbing_machine
from ..machines.work_holding import WorkHolding, load_work_holdings
from .records import Gear, Hob, load_gear

if TYPE_CHECKING:
    from ..db.connection import Connection

# mm the part under the gear (and the centre above it) stays inside the gear's root circle, on the
# radius: the hob's tip circle passes the root at the faces (run-out and approach), and a Ø20
# fixture under a Ø20.6 root is refused (issue 29) once a crowned or tapered root dips below it.
CLEARANCE = 0.5
# mm beyond the hob's tip diameter the part under the gear stands the machine's fixture below the
# gear: the hob centre runs in at most its tip radius below the face (§B7 approach E ≤ d_a0/2, plus
# 1–3 mm of safety) and its tip circle reaches a tip radius further down.
HEIGHT_MARGIN = 5.0
ADD_ONE = "add one with `engine fixtures import FILE.csv`"


class Setting(msgspec.Struct, frozen=True):
    """What the choice weighs: the gear's least root (mm), the hob, the machine."""
    gear: Gear
    hob: Hob
    machine: Machine

    @property
    def root(self) -> float:
        return least_root(self.gear)

    @property
    def largest(self) -> float:
        """The largest diameter that clears the root by CLEARANCE on the radius."""
        return self.root - 2 * CLEARANCE

    @property
    def height_needed(self) -> float:
        """Height under the gear that keeps the machine's fixture out of the hob's reach (0: it
        clears the root itself)."""
        if self.machine.fixture_diameter <= self.largest:
            return 0.0
        return max(0.0, self.hob.tip_diameter + HEIGHT_MARGIN - self.machine.fixture_gap)


def least_root(gear: Gear) -> float:
    """The smallest root diameter of the gear's units (mm): a taper's cone at its bottom face
    (d_f − 2·b·tan δ), a crowned root at its faces (d_f − 2·C_β/sin α_n, §B11)."""
    assert gear.root_diameter is not None   # a loaded gear is completed
    root = gear.root_diameter
    if gear.cone_angle:
        root -= 2 * gear.face_width * abs(math.tan(math.radians(gear.cone_angle)))
    if gear.crowning:
        root -= 2 * gear.crowning / math.sin(math.radians(gear.pressure_angle))
    units = [unit.root_diameter for unit in gear.units if unit.root_diameter is not None]
    return min([root, *units])


class HoldingTest(msgspec.Struct, frozen=True):
    """One required property: its name, what the holding offers, whether it fits, what is wanted."""
    name: str
    said: Callable[[WorkHolding, Setting], str]
    fits: Callable[[WorkHolding, Setting], bool]
    wanted: Callable[[Setting], str]
    offered: Callable[[WorkHolding], str]


HOLDING_TESTS: tuple[HoldingTest, ...] = (
    HoldingTest("machine",
                said=lambda h, s: f"fits {h.machine or 'any hobber'}",
                fits=lambda h, s: h.machine in (None, s.machine.name),
                wanted=lambda s: f"made for machine {s.machine.name} or for any hobber",
                offered=lambda h: f"is made for machine {h.machine}"),
    HoldingTest("diameter",
                said=lambda h, s: f"Ø{h.diameter:g} ≤ Ø{s.largest:g} (root Ø{s.root:g} − 2·{CLEARANCE:g})",
                fits=lambda h, s: h.diameter <= s.largest + 1e-9,
                wanted=lambda s: f"of at most Ø{s.largest:g} (root Ø{s.root:g} − 2·{CLEARANCE:g})",
                offered=lambda h: f"is Ø{h.diameter:g}"),
    HoldingTest("centre",
                said=lambda h, s: (f"centre Ø{h.tailstock_diameter:g} ≤ Ø{s.largest:g}" if h.tailstock_diameter
                                   else "no centre"),
                fits=lambda h, s: h.tailstock_diameter <= s.largest + 1e-9,
                wanted=lambda s: f"with a centre of at most Ø{s.largest:g}, or none",
                offered=lambda h: f"has a centre Ø{h.tailstock_diameter:g}"),
    HoldingTest("height",
                said=lambda h, s: (f"height {h.height:g} ≥ {s.height_needed:g} (hob da0 {s.hob.tip_diameter:g} "
                                   f"+ {HEIGHT_MARGIN:g} − gap {s.machine.fixture_gap:g}: the machine's fixture "
                                   f"Ø{s.machine.fixture_diameter:g} below stays out of the hob's reach)"
                                   if s.height_needed else f"height {h.height:g}"),
                fits=lambda h, s: h.height >= s.height_needed - 1e-9,
                wanted=lambda s: (f"at least {s.height_needed:g} mm high, to keep the machine's fixture "
                                  f"Ø{s.machine.fixture_diameter:g} out of the hob's reach (hob da0 "
                                  f"{s.hob.tip_diameter:g} + {HEIGHT_MARGIN:g} − gap {s.machine.fixture_gap:g})"),
                offered=lambda h: f"is {h.height:g} mm high"),
)


class HoldingChoice(msgspec.Struct, frozen=True):
    """The job's work-holding (None: the machine record's fixture and tailstock) and why."""
    holding: WorkHolding | None
    reason: str


class NoHoldingError(EngineError):
    """No work-holding fits; `property_name` is the first property none has."""

    def __init__(self, message: str, property_name: str) -> None:
        super().__init__(message)
        self.property_name = property_name


class GivenHoldingError(NoHoldingError, InputError):
    """The --fixture given does not fit the gear or the machine whatever the hob: the search stops
    at it (its height alone depends on the hob's tip diameter, so a short one is a choice's refusal)."""


HOB_DEPENDENT = frozenset({"height"})   # the HOLDING_TESTS whose verdict another hob may change


def machine_clears(setting: Setting) -> bool:
    """The machine record's fixture and tailstock clear the root (the job needs no work-holding)."""
    machine = setting.machine
    return max(machine.fixture_diameter, machine.tailstock_diameter) <= setting.largest + 1e-9


def machine_reason(setting: Setting) -> str:
    machine = setting.machine
    return (f"the machine's own: {machine.name}'s fixture Ø{machine.fixture_diameter:g} and tailstock "
            f"Ø{machine.tailstock_diameter:g} ≤ Ø{setting.largest:g} (root Ø{setting.root:g} − 2·{CLEARANCE:g})")


def choose_holding(gear: Gear, hob: Hob, machine: Machine, holdings: list[WorkHolding],
                   given: str | None = None) -> HoldingChoice:
    """The work-holding for the gear (see the module notes), or the one `given` by id if it
    fits; NoHoldingError naming the first unmet property. Without `given`, the machine's own
    when it clears, and the machine's own too when no work-holding fits (the simulation then
    judges it, as before issue 29)."""
    setting = Setting(gear, hob, machine)
    if given is not None:
        return _given(setting, holdings, given)
    if machine_clears(setting):
        return HoldingChoice(None, machine_reason(setting))
    try:
        return best_holding(setting, holdings)
    except NoHoldingError as refusal:
        return HoldingChoice(None, f"the machine's own (no work-holding of the library fits: {refusal})")


def best_holding(setting: Setting, holdings: list[WorkHolding]) -> HoldingChoice:
    """The largest work-holding that passes every test (then the largest centre, then the id)."""
    candidates = list(holdings)
    for test in HOLDING_TESTS:
        passing = [holding for holding in candidates if test.fits(holding, setting)]
        if not passing:
            raise NoHoldingError(_refusal(setting, test, candidates), test.name)
        candidates = passing
    best = min(candidates, key=lambda h: (-h.diameter, -h.tailstock_diameter, h.id))
    return HoldingChoice(best, f"{best.id} ({best.kind}): " + ", ".join(test.said(best, setting)
                                                                        for test in HOLDING_TESTS))


def _given(setting: Setting, holdings: list[WorkHolding], given: str) -> HoldingChoice:
    found = next((holding for holding in holdings if holding.id.upper() == given.upper()), None)
    if found is None:
        raise InputError(f"work-holding {given!r} does not exist; see `engine fixtures list`")
    unmet = next((test for test in HOLDING_TESTS if not test.fits(found, setting)), None)
    if unmet is not None:
        error = NoHoldingError if unmet.name in HOB_DEPENDENT else GivenHoldingError
        raise error(f"gear {setting.gear.id}: {found.kind} {found.id} does not fit: the job needs a "
                    f"work-holding {unmet.wanted(setting)}, and {found.id} {unmet.offered(found)}; "
                    f"`engine fixtures match --gear {setting.gear.id}` names one that fits", unmet.name)
    return HoldingChoice(found, f"{found.id} ({found.kind}, given): " + ", ".join(
        test.said(found, setting) for test in HOLDING_TESTS))


def _refusal(setting: Setting, test: HoldingTest, candidates: list[WorkHolding]) -> str:
    if not candidates:
        return f"gear {setting.gear.id}: the work-holding library is empty; {ADD_ONE}"
    ordered = sorted(candidates, key=lambda h: (h.diameter, h.id))
    offered = ", ".join(f"{holding.id} {test.offered(holding)}" for holding in ordered[:3])
    more = ", …" if len(candidates) > 3 else ""
    return (f"gear {setting.gear.id}: the job needs a work-holding {test.wanted(setting)}, and none is: "
            f"{offered}{more}; {ADD_ONE}")


def match_holding(conn: Connection, gear_id: int, machine_name: str | None = None) -> tuple[Hob, HoldingChoice]:
    """The hob `engine hobs match` chooses for the stored gear and the work-holding chosen with it."""
    from .hob_library import match_hob  # the library module imports the CSV reader: only here

    hob = match_hob(conn, gear_id).hob
    machine = hobbing_machine(conn, machine_name)
    return hob, choose_holding(load_gear(conn, gear_id), hob, machine, load_work_holdings(conn))
