"""Choosing a hob from the library for a gear (paper §4: automatic tool matching).

Each required property is a row of HOB_TESTS; the library is narrowed row by row, so a
refusal names the first property that no remaining hob has, and what the remaining hobs
offer instead. Among the hobs that pass, the same hand as the gear comes first, then the
coarsest sufficient class (fine hobs are kept for fine gears), then the id.
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable
from contextvars import ContextVar

import msgspec

from ..errors import EngineError
from .hob_geometry import generating_length, hob_axial_module, lead_angle
from .records import Gear, Hob

# Hob accuracy classes from best to coarsest (DIN 3968 / GB/T 6084).
ACCURACY_CLASSES = ("AAA", "AA", "A", "B", "C", "D")
# Coarsest hob class that still cuts a gear of a quality grade (GB/T 10095), finest grade first.
REQUIRED_CLASS_BY_GRADE = ((5, "AAA"), (7, "AA"), (8, "A"), (9, "B"), (10, "C"), (12, "D"))
DEFAULT_GRADE = 8
PURPOSES = ("cylindrical", "worm_wheel")
ANGLE_TOLERANCE = 1e-6
MODULE_TOLERANCE = 1e-6
# A worm-wheel hob's axial module against the wheel's (mm): 0.001 mm of module is π µm of pitch,
# within the single axial pitch tolerance of a class AA hob (DIN 3968, a few µm) [K]; it absorbs a
# helix angle rounded to 0.01° (7e-6 mm at m 3, γ 4°), not a hob of another worm.
AXIAL_MODULE_TOLERANCE = 0.001
# A worm-wheel hob copies its worm: its lead angle must be the wheel's helix angle.
LEAD_ANGLE_TOLERANCE = 0.5   # degrees
SHIFT_MARGIN = 5.0           # mm kept unused at each end of the hob (§B15 "margins")
ADD_A_HOB = "add one with `engine hobs add …` or `engine hobs import FILE.csv`"


class HobChoice(msgspec.Struct, frozen=True):
    """The hob chosen for a gear and why (engine hobs match says it)."""
    hob: Hob
    reason: str


class NoHobError(EngineError):
    """No hob of the library fits; `property_name` is the first property none has."""

    def __init__(self, message: str, property_name: str) -> None:
        super().__init__(message)
        self.property_name = property_name


class Need(msgspec.Struct, frozen=True):
    """What a gear asks of its hob."""

    purpose: str
    grade: int
    accuracy_class: str
    hand: str
    generating: float
    shift_travel: float

    @property
    def length(self) -> float:
        return self.generating + self.shift_travel + 2 * SHIFT_MARGIN


def required_class(quality_grade: int | None) -> str:
    grade = quality_grade if quality_grade is not None else DEFAULT_GRADE
    for finest_grade, hob_class in REQUIRED_CLASS_BY_GRADE:
        if grade <= finest_grade:
            return hob_class
    return ACCURACY_CLASSES[-1]


def _class_rank(accuracy_class: str) -> int:
    return ACCURACY_CLASSES.index(accuracy_class) if accuracy_class in ACCURACY_CLASSES else len(ACCURACY_CLASSES)


def _lead(hob: Hob) -> float:
    return lead_angle(hob.module, hob.starts, hob.tip_diameter)


def _module_distance(gear: Gear, hob: Hob) -> float:
    """How far the hob's module is from the gear's (mm). A worm-wheel hob, however its record
    states its module, is held to the wheel by axial module: its axial pitch π·m_n0/cos γ0 must be
    the wheel's transverse pitch π·m_n/cos γ (γ the wheel's helix, its worm's lead; DIN 3975),
    though an oversize hob's lead may differ a little (LEAD_ANGLE_TOLERANCE). A hob matched by
    normal module within that lead tolerance could cut a 4-start wheel's teeth 0.33 % too far apart
    (adversary 29). A cylindrical hob matches by normal module."""
    if hob.purpose == "worm_wheel":
        return abs(hob_axial_module(hob.module, hob.starts, hob.tip_diameter)
                   - gear.module / math.cos(math.radians(gear.helix_angle)))
    return abs(hob.module - gear.module)


def _module_fits(gear: Gear, hob: Hob) -> bool:
    tolerance = AXIAL_MODULE_TOLERANCE if hob.purpose == "worm_wheel" else MODULE_TOLERANCE
    return _module_distance(gear, hob) < tolerance


def _module_said(hob: Hob) -> str:
    """A worm-wheel hob by the axial module it is held to (and its record's kind), else by module."""
    if hob.purpose != "worm_wheel":
        return f"module {_n(hob.module)}"
    axial = round(hob_axial_module(hob.module, hob.starts, hob.tip_diameter), 6)
    return f"axial module {_n(axial)}" + ("" if hob.module_kind == "axial" else f" (normal {_n(hob.module)})")


def _module_wanted(gear: Gear, purpose: str) -> str:
    if purpose == "worm_wheel":
        return f"axial module {_n(round(gear.module / math.cos(math.radians(gear.helix_angle)), 6))}"
    return f"module {_n(gear.module)}"


# A refusal says the gear's need and what the hobs offer with `g` (6 significant digits) and the
# formats below; where the need would then read as one of the offers (module 3.98478 and 3.98478,
# 0.000003 apart: outside the 1e-6 of MODULE_TOLERANCE), it says them all with more digits.
SHOWN_DIGITS: ContextVar[int | None] = ContextVar("shown_digits", default=None)
MORE_DIGITS = (None, 10, 17)   # 17 significant digits tell any two doubles apart
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?")


def _n(value: float, usual: str = "g") -> str:
    """A number as a refusal says it: in its usual format, or with the digits _refusal chose."""
    digits = SHOWN_DIGITS.get()
    return format(value, usual if digits is None else f".{digits}g")


def _first_number(text: str) -> float | None:
    found = NUMBER.search(text)
    return float(found.group()) if found else None


class HobTest(msgspec.Struct, frozen=True):
    """One property of a hob, for the gears of `purposes`. A required test narrows the
    library (`fits`); a preference only orders it. `wanted` says what the gear needs,
    `offered` what a hob has and `distance` how far that is from the need (refusals list
    the closest first); `said` is the property in the reason of a choice."""

    name: str
    purposes: tuple[str, ...]
    said: Callable[[Gear, Hob, Need], str]
    fits: Callable[[Gear, Hob, Need], bool] | None = None
    wanted: Callable[[Gear, Need], str] | None = None
    offered: Callable[[Hob], str] | None = None
    distance: Callable[[Gear, Hob, Need], float] | None = None

    @property
    def required(self) -> bool:
        return self.fits is not None


def _hand_preference(gear: Gear, hob: Hob, need: Need) -> str:
    if gear.hand is None:
        return f"hand {hob.hand} (the gear has no hand; {need.hand} preferred)"
    if hob.hand == gear.hand:
        return f"same hand ({hob.hand})"
    return f"opposite hand ({hob.hand}; no {gear.hand}-hand hob fits)"


def _length_said(gear: Gear, hob: Hob, need: Need) -> str:
    return (f"length {hob.length:g} ≥ {need.length:.1f} needed (generating {need.generating:.1f} "
            f"+ shift {need.shift_travel:g} + margins {2 * SHIFT_MARGIN:g})")


BOTH = PURPOSES
HOB_TESTS: tuple[HobTest, ...] = (
    HobTest("purpose", BOTH,
            said=lambda gear, hob, need: f"purpose {hob.purpose}",
            fits=lambda gear, hob, need: hob.purpose == need.purpose,
            wanted=lambda gear, need: f"purpose {need.purpose}",
            offered=lambda hob: f"purpose {hob.purpose}",
            distance=lambda gear, hob, need: 0.0),
    HobTest("module", BOTH,
            said=lambda gear, hob, need: _module_said(hob),
            fits=lambda gear, hob, need: _module_fits(gear, hob),
            wanted=lambda gear, need: _module_wanted(gear, need.purpose),
            offered=_module_said,
            distance=lambda gear, hob, need: _module_distance(gear, hob)),
    HobTest("pressure angle", BOTH,
            said=lambda gear, hob, need: f"pressure angle {hob.pressure_angle:g}°",
            fits=lambda gear, hob, need: abs(hob.pressure_angle - gear.pressure_angle) < ANGLE_TOLERANCE,
            wanted=lambda gear, need: f"pressure angle {_n(gear.pressure_angle)}°",
            offered=lambda hob: f"pressure angle {_n(hob.pressure_angle)}°",
            distance=lambda gear, hob, need: abs(hob.pressure_angle - gear.pressure_angle)),
    HobTest("accuracy class", BOTH,
            said=lambda gear, hob, need: (f"class {hob.accuracy_class} (grade {need.grade} needs "
                                          f"{need.accuracy_class} or better)"),
            fits=lambda gear, hob, need: _class_rank(hob.accuracy_class) <= _class_rank(need.accuracy_class),
            wanted=lambda gear, need: f"class {need.accuracy_class} or better (grade {need.grade})",
            offered=lambda hob: f"class {hob.accuracy_class}",
            distance=lambda gear, hob, need: _class_rank(hob.accuracy_class) - _class_rank(need.accuracy_class)),
    HobTest("hand", ("cylindrical",), said=_hand_preference),
    HobTest("hand", ("worm_wheel",),
            said=lambda gear, hob, need: f"hand {hob.hand} (the wheel's, required)",
            fits=lambda gear, hob, need: hob.hand == need.hand,
            wanted=lambda gear, need: f"hand {need.hand}",
            offered=lambda hob: f"hand {hob.hand}",
            distance=lambda gear, hob, need: 0.0),
    HobTest("lead angle", ("worm_wheel",),
            said=lambda gear, hob, need: (f"lead angle {_lead(hob):.2f}° (helix {gear.helix_angle:g}° "
                                          f"± {LEAD_ANGLE_TOLERANCE:g}°)"),
            fits=lambda gear, hob, need: abs(_lead(hob) - gear.helix_angle) <= LEAD_ANGLE_TOLERANCE,
            wanted=lambda gear, need: f"lead angle {_n(gear.helix_angle)}° ± {LEAD_ANGLE_TOLERANCE:g}°",
            offered=lambda hob: f"lead angle {_n(_lead(hob), '.2f')}°",
            distance=lambda gear, hob, need: abs(_lead(hob) - gear.helix_angle)),
    HobTest("length", BOTH,
            said=_length_said,
            fits=lambda gear, hob, need: hob.length >= need.length,
            wanted=lambda gear, need: f"length ≥ {_n(need.length, '.1f')} mm",
            offered=lambda hob: f"length {_n(hob.length)}",
            distance=lambda gear, hob, need: need.length - hob.length),
)


def need_of(gear: Gear, purpose: str = "cylindrical", shift_travel: float = 0.0) -> Need:
    if purpose not in PURPOSES:
        raise EngineError(f"hob purpose {purpose!r} is not one of {', '.join(PURPOSES)}")
    if shift_travel < 0:
        raise EngineError(f"shift travel {shift_travel:g} mm is negative; give 0 or more")
    grade = gear.quality_grade if gear.quality_grade is not None else DEFAULT_GRADE
    return Need(purpose, grade, required_class(gear.quality_grade), gear.hand or "R",
                generating_length(gear.module, gear.pressure_angle), shift_travel)


def choose_hob(gear: Gear, hobs: list[Hob], *, purpose: str = "cylindrical",
               shift_travel: float = 0.0) -> HobChoice:
    """The best fitting hob for `gear` (see the module notes), with the reason: every
    property checked and its values. Raises NoHobError naming the first unmet property."""
    return matching_hobs(gear, hobs, purpose=purpose, shift_travel=shift_travel)[0]


def matching_hobs(gear: Gear, hobs: list[Hob], *, purpose: str = "cylindrical",
                  shift_travel: float = 0.0) -> list[HobChoice]:
    """Every hob that passes the required tests, best first (choose_hob's order: the gear's hand,
    the coarsest sufficient class, the id), each with its reason: the search before a refusal
    (engine.programs.job_search) tries the others when the best does not fit the job. Raises
    NoHobError naming the first property no hob has."""
    need = need_of(gear, purpose, shift_travel)
    tests = [test for test in HOB_TESTS if purpose in test.purposes]
    candidates, position = _accepted(gear, list(hobs), need, tests)
    if position is not None:
        raise NoHobError(_refusal(gear, need, tests[position], tests[:position], candidates), tests[position].name)
    candidates.sort(key=lambda hob: (hob.hand != need.hand, -_class_rank(hob.accuracy_class), hob.id))
    return [HobChoice(hob, f"{hob.id}: " + ", ".join(test.said(gear, hob, need) for test in tests))
            for hob in candidates]


def _accepted(gear: Gear, hobs: list[Hob], need: Need, tests: list[HobTest]) -> tuple[list[Hob], int | None]:
    """The hobs that pass every required test, narrowed in the order of `tests`, and None; or,
    when none is left, the hobs that reached the first test none passes, and that test's position.
    The one acceptance of the engine: a new job's hob (choose_hob) and a stored job's (unmet_need)."""
    candidates = hobs
    for position, test in enumerate(tests):
        fits = test.fits
        if fits is None:   # not required: a preference only orders the hobs
            continue
        passing = [hob for hob in candidates if fits(gear, hob, need)]
        if not passing:
            return candidates, position
        candidates = passing
    return candidates, None


def unmet_need(gear: Gear, hob: Hob, *, purpose: str = "cylindrical", shift_travel: float = 0.0) -> str | None:
    """What the gear needs that `hob` does not have ("module 2, the hob has module 2.5"), the first
    property choose_hob would refuse it for; None if choose_hob accepts it for the gear (a stored
    job naming its hob is held to the same tests as a new job, issue 26)."""
    need = need_of(gear, purpose, shift_travel)
    tests = [test for test in HOB_TESTS if purpose in test.purposes]
    position = _accepted(gear, [hob], need, tests)[1]
    if position is None:
        return None
    test = tests[position]
    assert test.wanted is not None and test.offered is not None   # a required test says both
    return f"{test.wanted(gear, need)}, the hob has {test.offered(hob)}"


def _closest(gear: Gear, need: Need, test: HobTest, hobs: list[Hob], groups: int = 3) -> str:
    """What the hobs offer for the test's property, closest to the need first, with ids."""
    offered, distance = test.offered, test.distance
    assert offered is not None and distance is not None   # a required test says both
    by_value: dict[str, list[Hob]] = {}
    for hob in hobs:
        by_value.setdefault(offered(hob), []).append(hob)
    ordered = sorted(by_value.items(),
                     key=lambda item: min(abs(distance(gear, hob, need)) for hob in item[1]))
    shown = [f"{value} ({', '.join(hob.id for hob in group[:3])}{', …' if len(group) > 3 else ''})"
             for value, group in ordered[:groups]]
    return ", ".join(shown) + (", …" if len(ordered) > groups else "")


def _refusal(gear: Gear, need: Need, test: HobTest, earlier: list[HobTest], candidates: list[Hob]) -> str:
    """The refusal said with the fewest digits (MORE_DIGITS) at which the need reads as none of the
    offers."""
    for digits in MORE_DIGITS:
        token = SHOWN_DIGITS.set(digits)
        try:
            if digits == MORE_DIGITS[-1] or not _reads_alike(gear, need, test, candidates):
                return _said_refusal(gear, need, test, earlier, candidates)
        finally:
            SHOWN_DIGITS.reset(token)
    raise AssertionError("unreachable: the last digits always return")


def _reads_alike(gear: Gear, need: Need, test: HobTest, candidates: list[Hob]) -> bool:
    """Whether the need's number, as now shown, reads as the number of a hob's offer."""
    assert test.wanted is not None and test.offered is not None   # the test refused is a required one
    wanted = _first_number(test.wanted(gear, need))
    return wanted is not None and wanted in {_first_number(test.offered(hob)) for hob in candidates}


def _said_refusal(gear: Gear, need: Need, test: HobTest, earlier: list[HobTest], candidates: list[Hob]) -> str:
    wanted = [t.wanted for t in earlier if t.required]
    earlier_wanted = [said(gear, need) for said in wanted if said is not None]   # a required test says it
    among = f" among those with {', '.join(earlier_wanted)}" if earlier_wanted else ""
    if not candidates:
        offered = "the hob library is empty"
    else:
        offered = ("they have " if earlier_wanted else "the library has ") + _closest(gear, need, test, candidates)
    assert test.wanted is not None   # the test refused is a required one
    return f"gear {gear.id}: no hob has {test.wanted(gear, need)}{among}: {offered}; {ADD_A_HOB}"
