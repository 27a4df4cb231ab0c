"""Choosing a hob from the library for a gear (paper §4: automatic tool matching)."""
from __future__ import annotations

from dataclasses import dataclass

from .errors import EngineError
from .records import Gear, Hob

# Hob accuracy classes from best to coarsest (DIN 3968 / GB/T 6084).
ACCURACY_CLASSES = ("AAA", "AA", "A", "B", "C", "D")
# Coarsest hob class that still cuts a gear of a quality grade (GB/T 10095), finest grade first.
REQUIRED_CLASS_BY_GRADE = ((5, "AAA"), (7, "AA"), (8, "A"), (9, "B"), (10, "C"), (12, "D"))
ANGLE_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HobChoice:
    hob: Hob
    reason: str


def required_class(quality_grade: int | None) -> str:
    grade = quality_grade if quality_grade is not None else 8
    for finest_grade, hob_class in REQUIRED_CLASS_BY_GRADE:
        if grade <= finest_grade:
            return hob_class
    return ACCURACY_CLASSES[-1]


def _class_rank(accuracy_class: str) -> int:
    return ACCURACY_CLASSES.index(accuracy_class) if accuracy_class in ACCURACY_CLASSES else len(ACCURACY_CLASSES)


# Each test: (property named in the refusal, predicate over (gear, hob, needed class)).
HOB_TESTS = (
    ("module", lambda gear, hob, needed: abs(hob.module - gear.module) < ANGLE_TOLERANCE),
    ("pressure angle", lambda gear, hob, needed: abs(hob.pressure_angle - gear.pressure_angle) < ANGLE_TOLERANCE),
    ("accuracy class", lambda gear, hob, needed: _class_rank(hob.accuracy_class) <= _class_rank(needed)),
)


def choose_hob(gear: Gear, hobs: list[Hob]) -> HobChoice:
    """The best fitting hob: every test passes; then same hand as the gear, coarsest
    sufficient class (keep fine hobs for fine gears), fewest starts... by id for a tie."""
    needed = required_class(gear.quality_grade)
    candidates = list(hobs)
    for name, test in HOB_TESTS:
        passing = [hob for hob in candidates if test(gear, hob, needed)]
        if not passing:
            raise EngineError(_refusal(gear, name, needed, candidates))
        candidates = passing
    candidates.sort(key=lambda hob: (hob.hand != (gear.hand or "R"), -_class_rank(hob.accuracy_class), hob.id))
    best = candidates[0]
    hand_note = "same hand as the gear" if best.hand == (gear.hand or best.hand) else "opposite hand (no same-hand hob)"
    reason = (f"module {best.module:g}, pressure angle {best.pressure_angle:g}°, class {best.accuracy_class} "
              f"(grade {gear.quality_grade or 8} needs {needed} or better), {hand_note}")
    return HobChoice(best, reason)


def _refusal(gear: Gear, property_name: str, needed: str, candidates: list[Hob]) -> str:
    values = {"module": f"module {gear.module:g}", "pressure angle": f"pressure angle {gear.pressure_angle:g}°",
              "accuracy class": f"accuracy class {needed} or better for grade {gear.quality_grade}"}
    return (f"gear {gear.id}: no hob in the library has {values[property_name]} "
            f"({len(candidates)} hob(s) left after the earlier checks); add one to the hob table")
