"""The search before a refusal (issue 29): a gear the first choice does not fit is tried with the
alternatives a skilled programmer would try, and refused only when none fits.

The first choice is the model's: climb, the best hob of engine.gears.hob_matching.choose_hob,
the cuts by module (Choices.cut_count). When it is refused for a fit reason (the model's
refusal, e.g. the hob reaching a duplex gear's other unit; a speed limit; the verifier's or the
simulation's refusal of the made program), the alternatives of SEARCH_ORDER are tried in order,
each one planned, verified and proved exactly as the first (engine.programs.verified_run): the
first that is proved is taken, and a note says which choice was taken and why. A choice the user
gave (--feed-mode, --cuts) is never varied. Nothing of an attempt that is refused is kept, so no
unproved program is ever stored or printed. An input no choice changes (engine.errors.InputError:
an unknown --fixture, two cuts with a tangential feed, …) and a template that fails to run stop
the search at once with their own words.
"""
from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import msgspec
from msgspec.structs import replace

from ..errors import EngineError, InputError
from ..hobbing.choices import DEFAULT_FEED_MODE, FEED_MODES, UNIT_FEED_MODES, UNIT_SEPARATOR, Choices
from ..templates.decision_table import TemplateError

if TYPE_CHECKING:
    from ..gears.records import Hob

MAX_HOBS = 3        # hobs tried at most: the best and the next two that pass every test of choose_hob
NOTHING_STORED = "; nothing stored"

# What the search varies, in this order (issue 29). The attempts are the product of the rows with
# the first row varying fastest: a change that keeps the hob and the cuts (the pass direction: only
# the pass ends move) is tried before another hob (a tool change on the machine), and both before a
# second cut (a longer cycle). A row whose choice the user gave has that value only.
SEARCH_ORDER: tuple[tuple[str, str], ...] = (
    ("feed direction", "climb, then conventional, then conventional-climb (rough conventional, finish climb); "
                       "a cluster gear then each unit its own way (climb/conventional, conventional/climb)"),
    ("hob", f"the best hob, then the others choose_hob accepts, in its order (hand, class, id); {MAX_HOBS} at most"),
    ("cuts", "the model's count (one up to m 3, §B14), then two cuts (rough, then finish)"),
)


class Attempt(msgspec.Struct, frozen=True):
    """One choice of the search: the hob and the job's choices (feed mode and cuts resolved)."""
    hob: Hob
    choices: Choices
    given: frozenset[str] = frozenset()   # the names of the choices the user gave ("feed_mode", "cuts")

    def cut_count(self, module: float) -> int:
        return self.choices.cut_count(module)

    def said(self, module: float) -> str:
        """'conventional, hob H-M2-A-L1, 1 cut' (a choice the user gave marked so)."""
        count = self.cut_count(module)
        mode = self.choices.mode + (" (given)" if "feed_mode" in self.given else "")
        cuts = f"{count} cut{'s' if count > 1 else ''}" + (" (given)" if "cuts" in self.given else "")
        return f"{mode}, hob {self.hob.id}, {cuts}"

    def key(self, module: float) -> tuple:
        """What makes two attempts the same job: a single cut runs the roughing direction only, so
        conventional and conventional-climb are one job then."""
        count = self.cut_count(module)
        return self.hob.id, count, self.choices.directions(count, self.units)

    @property
    def units(self) -> int:
        """The units the mode names a direction for (a cluster gear's two, or one for all)."""
        return len(self.choices.mode.split(UNIT_SEPARATOR))


def attempts(hobs: list[Hob], choices: Choices, module: float, units: int = 1,
             axial: bool = True) -> list[Attempt]:
    """The first choice, then the alternatives of SEARCH_ORDER (the same job once); a gear of two
    units (a cluster gear) also tries each unit fed its own way (UNIT_FEED_MODES). A gear cut
    without axial passes (`axial` false: a worm wheel) has no feed direction to vary."""
    given = frozenset(name for name in ("feed_mode", "cuts") if getattr(choices, name) is not None)
    found: dict[tuple, Attempt] = {}
    for cuts in _cut_choices(choices, module):
        for hob in hobs[:MAX_HOBS]:
            for mode in _feed_modes(choices, units) if axial else [choices.mode]:
                attempt = Attempt(hob, replace(choices, feed_mode=mode, cuts=cuts), given)
                found.setdefault(attempt.key(module), attempt)
    return list(found.values())


def _feed_modes(choices: Choices, units: int) -> list[str]:
    """The mode given, or the model's first and then the others (FEED_MODES order), then for a
    cluster gear those feeding each unit its own way."""
    if choices.feed_mode is not None:
        return [choices.feed_mode]
    per_unit = list(UNIT_FEED_MODES) if units == 2 else []
    return [DEFAULT_FEED_MODE] + [mode for mode in FEED_MODES if mode != DEFAULT_FEED_MODE] + per_unit


def _cut_choices(choices: Choices, module: float) -> list[int | None]:
    """The cuts given, or the model's (None: by module), then two where the model says one."""
    if choices.cuts is not None or choices.cut_count(module) == 2:
        return [choices.cuts]
    return [None, 2]


class Found(msgspec.Struct, frozen=True):
    """What the search took: the planned job, the attempt, and the notes saying why."""
    planned: Any
    attempt: Attempt
    notes: list


def first_that_fits(gear_id: int, module: float, tried: list[Attempt], plan: Callable[[Attempt], object]) -> Found:
    """plan(attempt) for each attempt in order until one is planned and proved; the refusals of the
    ones before it named in the note. None fits: the first attempt's refusal (its type kept), with
    every alternative tried and each distinct reason once, in one line."""
    refused: list[tuple[Attempt, EngineError]] = []
    for attempt in tried:
        try:
            planned = plan(attempt)
        except (TemplateError, InputError):
            raise   # the class's rows fail to run, or an input no choice changes: no choice is a way out
        except EngineError as error:
            refused.append((attempt, error))
            continue
        return Found(planned, attempt, [_note(gear_id, module, attempt, refused)] if refused else [])
    raise _refusal(gear_id, module, refused) from None


def reason(gear_id: int, error: EngineError) -> str:
    """The refusal without the gear's name and the trailing 'nothing stored' (said once around it)."""
    text = str(error)
    text = text.removeprefix(f"gear {gear_id}: ")
    return text.removesuffix(NOTHING_STORED)


def _note(gear_id: int, module: float, taken: Attempt, refused: list[tuple[Attempt, EngineError]]) -> str:
    """'gear 54: cut with [conventional, …], not the first choice: [climb, …] does not fit: <reason>'."""
    before = "; ".join(f"[{attempt.said(module)}] does not fit: {reason(gear_id, error)}" for attempt, error in refused)
    return f"gear {gear_id}: cut with [{taken.said(module)}], not the first choice: {before}"


def _refusal(gear_id: int, module: float, refused: list[tuple[Attempt, EngineError]]) -> EngineError:
    """The refusal when nothing fits, of the first attempt's type (a LimitError stays one), in one
    line a programmer reads: the first choice with its full reason, then every other choice tried in
    the search's order, each tagged with its reason's letter, and each distinct reason once (reasons
    equal but for their numbers are one: the same refusal at another hob's diameter). A reason
    the same for all is said once. A single attempt's refusal is unchanged."""
    first_attempt, first = refused[0]
    if len(refused) == 1:
        return first
    reasons = [reason(gear_id, error) for _, error in refused]
    message = (_all_alike(first, module, refused) if len(set(reasons)) == 1
               else _grouped(gear_id, module, refused, reasons))
    error = type(first).__new__(type(first))   # its type and attributes, the new line
    error.__dict__.update(first.__dict__)
    error.args = (message + NOTHING_STORED,)
    return error


def _all_alike(first: EngineError, module: float, refused: list[tuple[Attempt, EngineError]]) -> str:
    """'<the first refusal>; the same with every choice tried: [climb, …] (the first choice), […]'."""
    tried = [f"[{attempt.said(module)}]" for attempt, _ in refused]
    tried[0] += " (the first choice)"
    return f"{str(first).removesuffix(NOTHING_STORED)}; the same with every choice tried: {', '.join(tried)}"


def _grouped(gear_id: int, module: float, refused: list[tuple[Attempt, EngineError]], reasons: list[str]) -> str:
    """'gear 54: no choice fits: the first choice [climb, …] <reason>; also tried, in order: (a) […],
    […], (b) […]; (a) is the first choice's reason (numbers aside), (b) is: <reason>'."""
    shapes = [_shape(why) for why in reasons]
    distinct = list(dict.fromkeys(shapes))            # in the order first met; the first choice's is (a)
    letter = {shape: f"({_letter(n)})" for n, shape in enumerate(distinct)}
    also, last = [], None
    for (attempt, _), shape in zip(refused[1:], shapes[1:]):
        also.append(("" if shape == last else f"{letter[shape]} ") + f"[{attempt.said(module)}]")
        last = shape
    said = [f"{letter[distinct[0]]} is the first choice's reason" + (", numbers aside" if shapes.count(distinct[0]) > 1
                                                                     else "")]
    said += [f"{letter[shape]} is: {reasons[shapes.index(shape)]}" for shape in distinct[1:]]
    return (f"gear {gear_id}: no choice fits: the first choice [{refused[0][0].said(module)}] {reasons[0]}; "
            f"also tried, in order: {', '.join(also)}; {', and '.join(said)}")


def _shape(why: str) -> str:
    """A reason with its numbers (and ids holding them) blanked: two choices refused the same way."""
    return re.sub(r"[\w.+-]*\d[\w.+-]*", "#", why)


def _letter(n: int) -> str:
    return "abcdefghijklmnopqrstuvwxyz"[n] if n < 26 else f"r{n}"
