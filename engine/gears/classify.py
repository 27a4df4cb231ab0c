"""Group-technology classification of a gear that names no class (design notes §6).

The tree is walked as a tuple of rules asked in order — face-width variation first (cone,
crowning), then the generating line (helix) —; the first rule answered "yes" names the
leaf class, and a gear that answers "no" to all of them is `DEFAULT_CLASS`. Adding a rule
is adding a row to `RULES`, not another branch. Features no class combines (`CONFLICTS`)
are refused with the reason. Classes that the gear columns alone do not tell apart
(worm_wheel: the tooth profile comes from the worm; duplex: further units are imported
after the gear) are not classified: the gear CSV names them explicitly.

Worm wheels are not guessed either way (`looks_like_worm_wheel`): a gear without a class
whose data look like a worm wheel is refused with a request for its class, because a worm
wheel classified as helical is cut with a cylindrical hob and an axial pass: the wrong flank
on a bronze blank, scrapped.
"""
from __future__ import annotations

import re
from collections.abc import Callable, Collection, Mapping
from typing import TYPE_CHECKING, Any, cast

import msgspec

from ..errors import EngineError
from .hob_matching import choose_hob
from .models import HobbingModel, ancestry, registered_models
from .records import load_gear, load_hobs

if TYPE_CHECKING:
    from ..db.connection import Connection

DEFAULT_CLASS = "spur"


class Rule(msgspec.Struct, frozen=True):
    """If `field` of the gear is given and `holds` for its value, the gear is `gear_class`."""

    question: str
    field: str
    holds: Callable[[float], bool]
    gear_class: str


RULES: tuple[Rule, ...] = (
    Rule("has it further toothed units?", "units", lambda value: value > 0, "duplex"),
    Rule("is a cone angle given and not 0?", "cone_angle", lambda value: value != 0, "taper"),
    Rule("is a crowning given and greater than 0?", "crowning", lambda value: value > 0, "crowned"),
    Rule("is the helix angle not 0?", "helix_angle", lambda value: value != 0, "helical"),
)


# (fields both given and not 0, why no class fits them together)
CONFLICTS: tuple[tuple[tuple[str, str], str], ...] = (
    (("cone_angle", "crowning"), "no class hobs a crowned taper gear (cone angle and crowning both given)"),
)


# A worm wheel's helix angle is its worm's lead angle tan γ = z1·m_x/d1: 3.6°–7.1° for the usual
# single-start worms (diameter quotient q = d1/m_x of 8 to 16, DIN 3976), while helical gears are
# cut at 8°–45°. Worm wheels are bronze (CuSn12, CuAl10Ni: a copper alloy runs against a hardened
# steel worm); helical gears almost never are. What the drawing has: helix angle and material.
WORM_LEAD_ANGLE_MAX = 8.0          # degrees: a helix below this is a worm's lead angle, not a helix
COPPER_ALLOY = re.compile(r"^(g-?|gz-?|gc-?)?cu|bronze|brass", re.IGNORECASE)


def looks_like_worm_wheel(gear: Mapping[str, Any]) -> str | None:
    """Why a gear with a helix looks like a worm wheel (its helix angle is below a helical gear's
    and would be a worm's lead angle, or its material is a copper alloy), or None. Either sign
    is enough: refusing a genuine small-helix or bronze helical gear costs the engineer one
    explicit class; guessing a worm wheel as helical costs the blank."""
    helix = given_number(gear, "helix_angle")
    if not helix:
        return None
    material = str(gear.get("material") or "")
    signs = [f"helix angle {helix:g}° below {WORM_LEAD_ANGLE_MAX:g}°, a worm's lead angle"] \
        if helix < WORM_LEAD_ANGLE_MAX else []
    signs += [f"material {material}, a copper alloy"] if COPPER_ALLOY.search(material) else []
    return " and ".join(signs) or None


# class a rule found -> (question, the signs that the gear is another class instead, that class)
ASK_INSTEAD = {"helical": ("does it look like a worm wheel?", looks_like_worm_wheel, "worm_wheel")}

# What to do when no class fits: the usual remedy (a conflict of features may name another one)
NAME_THE_CLASS = "give gear_class explicitly"


class Classification(msgspec.Struct, frozen=True):
    """The leaf class a gear falls in (None: no class fits, see `problem`), and the
    questions and answers that led there."""

    gear_class: str | None
    path: list[tuple[str, str]] = []
    problem: str | None = None
    remedy: str = NAME_THE_CLASS

    def explain(self) -> str:
        """One line: `question? no → question? yes → helical`."""
        steps = [f"{question} {answer}" for question, answer in self.path]
        return " → ".join(steps + [self.gear_class or f"no class: {self.problem}"])


def given_number(gear: Mapping[str, Any], name: str) -> float | None:
    """The gear's value of `name` as a float, or None when it is absent or empty."""
    value = gear.get(name)
    if value is None or (isinstance(value, str) and not value.strip()):
        return None
    return float(value)


def _answer(rule: Rule, gear: Mapping[str, Any]) -> str:
    value = given_number(gear, rule.field)
    if value is None:
        return "no (not given)"
    return f"{'yes' if rule.holds(value) else 'no'} ({rule.field} = {value:g})"


def classify(gear: Mapping[str, Any]) -> Classification:
    """The leaf class of `gear` (a mapping of gear CSV column names to values) by `RULES`.

    Each step of `.path` is (question, answer); an answer starts with "yes" or "no" and
    names the value it looked at."""
    path: list[tuple[str, str]] = []
    for (first, second), reason in CONFLICTS:
        values = (given_number(gear, first), given_number(gear, second))
        if all(values):
            path.append((f"are {first} and {second} both given?", f"yes ({values[0]:g}, {values[1]:g})"))
            return Classification(None, path, reason)
    for rule in RULES:
        answer = _answer(rule, gear)
        path.append((rule.question, answer))
        if answer.startswith("yes"):
            return _asked_first(rule.gear_class, gear, path)
    return Classification(DEFAULT_CLASS, path)


def _asked_first(gear_class: str, gear: Mapping[str, Any], path: list) -> Classification:
    """The class found, unless the gear also looks like a class the tree must not guess
    (ASK_INSTEAD): then no class, and the request to name it."""
    for found, (question, signs_of, other) in ASK_INSTEAD.items():
        signs = signs_of(gear) if found == gear_class else None
        if signs:
            path.append((question, f"yes ({signs})"))
            said = other.replace("_", " ")
            return Classification(None, path, f"looks like a {said} ({signs}); the tree does not guess {said}s",
                                  f"give gear_class {other} (or {found}) explicitly")
    return Classification(gear_class, path)


def not_installed_message(gear_id: Any, gear_class: str) -> str:
    """What to say when a gear is classified into a class the database does not have."""
    return (f"gear {gear_id}: classified as {gear_class}, but no gear class '{gear_class}' is "
            f"installed; give gear_class explicitly or add the class "
            f"(engine template import --class {gear_class} …)")


def classify_installed(gear: Mapping[str, Any], installed: Collection[str]) -> Classification:
    """`classify(gear)`, raising EngineError when the class found is not in `installed`."""
    classification = classify(gear)
    gear_id = gear.get("gear_id", gear.get("id", "?"))
    if classification.gear_class is None:
        raise EngineError(f"gear {gear_id}: {classification.problem}; {classification.remedy}")
    if classification.gear_class not in installed:
        raise EngineError(not_installed_message(gear_id, classification.gear_class))
    return classification


class GearClassReport(msgspec.Struct, frozen=True):
    """What `engine classify --gear ID` says: the stored class, the automatic decision path,
    and the hobbing model and hob the gear gets."""

    gear_id: int
    stored_class: str | None
    classification: Classification
    model_class: str | None
    hob: str | None
    without_units: str | None = None   # the tree's class of the gear without its further units

    def lines(self) -> list[str]:
        automatic = self.classification.gear_class
        said = [f"gear {self.gear_id}: class {self.stored_class}",
                f"  decision path: {self.classification.explain()}"]
        if self.stored_class != automatic:
            said.append(self._why_stored(automatic))
        said.append(f"  hobbing model: {self.model_class or 'none: no class on the path up has a model'}")
        said.append(f"  hob: {self.hob}")
        return said

    def _why_stored(self, automatic: str | None) -> str:
        """Why the stored class is not the tree's. The database does not keep whether the gear file
        named the class: a class the tree gives the gear without its further units may have been
        classified at import, before `engine gears units` added them; any other was named."""
        if self.without_units is not None and self.stored_class == self.without_units:
            return (f"  class {self.stored_class} is the tree's for the gear without its further units (classified "
                    f"or named before `engine gears units` added them); to have class {automatic}, import the gear "
                    f"again with gear_class {automatic} or empty (`engine gears import FILE.csv --replace`)")
        return (f"  the gear file named class {self.stored_class} explicitly "
                f"(the tree alone gives {automatic or 'no class'})")


def explain_gear(conn: Connection, gear_id: int) -> GearClassReport:
    """Classify a stored gear again and say how; also the model and hob it gets."""
    gear = load_gear(conn, gear_id)
    features = {"gear_id": gear.id, "cone_angle": gear.cone_angle, "crowning": gear.crowning,
                "helix_angle": gear.helix_angle, "material": gear.material}
    classification = classify({**features, "units": len(gear.units)})
    without_units = classify(features).gear_class if gear.units else None
    lineage = ancestry(conn, gear.gear_class) if gear.gear_class else []
    models = registered_models()
    model_class = next((name for name in lineage if name in models), None)
    hob = None
    if model_class:
        model = cast(HobbingModel, models[model_class])   # a gear's class is served by a hobbing model
        try:
            chosen = choose_hob(gear, load_hobs(conn), purpose=model.hob_purpose)
            hob = chosen.reason
        except EngineError as error:
            hob = f"none fits: {error}"
    return GearClassReport(gear_id, gear.gear_class, classification, model_class, hob, without_units)
