"""The one use of a kept variable the verifier reads: the hob shift per part of the hobbing
templates. The variable keeps the shift from part to part on the control, so its value is unknown
here; the clamp lines after the step put it in [lo, hi]. One form per dialect (CLAMPS, data):

840D, the R-parameter R11:              Fanuc Custom Macro B, the common variable #500
                                        (kept through power-off; fanuc-egb.md §F9):
    R11=R11+<step>  ; the shift             #500=#500+<step> (the shift)
    IF (R11<lo) OR (R11>hi)                 IF [#500 LT lo] THEN #500=lo
    R11=<reset>     ; lo <= reset <= hi     IF [#500 GT hi] THEN #500=lo
    ENDIF                                   G0 Y#500
    G0 Y=R11

The move is checked at both ends of that interval. Exactly these lines, in this order, and
nothing between them. On the 840D any other R-parameter use is refused by the block grammar
(engine.verifier.numbers); on Fanuc any other macro statement (another variable, GOTO, WHILE,
a bracket) is refused here in one line: the verifier cannot follow it."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, ClassVar, Literal

import msgspec

from .numbers import plain_decimal
from .refusals import Refused

if TYPE_CHECKING:
    from collections.abc import Callable

UNSIGNED = r"(\d+(?:\.\d*)?|\.\d+)"
DECIMAL = r"([-+]?(?:\d+(?:\.\d*)?|\.\d+))"


class ClampForm(msgspec.Struct, frozen=True):
    """A dialect's clamp: its variable, its lines in order (step name, pattern), how a reader is
    told the shape, what marks a line as an attempt at it, and whether such a line that is none
    of the forms is refused here (Fanuc: a macro statement) or left to the block grammar (840D)."""
    parameter: str
    forms: tuple[tuple[str, re.Pattern[str]], ...]
    shape: str
    marks: re.Pattern[str]
    refuse_others: bool

    @property
    def sequence(self) -> tuple[str, ...]:
        return tuple(step for step, _ in self.forms)


R11 = ClampForm(
    parameter="R11",
    forms=(("step", re.compile(rf"R11=R11\+{UNSIGNED}")),
           ("test", re.compile(rf"IF \(R11<{DECIMAL}\) OR \(R11>{DECIMAL}\)")),
           ("reset", re.compile(rf"R11={DECIMAL}")),
           ("end", re.compile(r"ENDIF")),
           ("move", re.compile(r"G0 Y=R11"))),
    shape="R11=R11+step, IF (R11<lo) OR (R11>hi), R11=lo…hi, ENDIF, G0 Y=R11",
    marks=re.compile(r"R11|IF"),
    refuse_others=False)
# Custom Macro B: conditions in brackets with LT/GT (OR is a bitwise operation on values, so two
# IF lines rather than one with OR), the kept common variable #500 (fanuc-egb.md §F9).
MACRO_500 = ClampForm(
    parameter="#500",
    forms=(("step", re.compile(rf"#500=#500\+{UNSIGNED}")),
           ("below", re.compile(rf"IF \[#500 LT {DECIMAL}\] THEN #500={DECIMAL}")),
           ("above", re.compile(rf"IF \[#500 GT {DECIMAL}\] THEN #500={DECIMAL}")),
           ("move", re.compile(r"G0 Y#500"))),
    shape="#500=#500+step, IF [#500 LT lo] THEN #500=lo, IF [#500 GT hi] THEN #500=lo, G0 Y#500",
    marks=re.compile(r"[#\[\]]|\b(?:IF|THEN|GOTO|WHILE|DO\d*|END\d*)\b"),
    refuse_others=True)
CLAMPS = {form.parameter: form for form in (R11, MACRO_500)}   # Dialect.shift_clamp names one


class ShiftLine(msgspec.Struct, frozen=True):
    """One of the hob-shift lines of a clamp form as read: its variable, which step and the numbers it gives."""
    kind: ClassVar[Literal["shift"]] = "shift"
    parameter: str
    step: str
    values: tuple[float, ...]


def read_shift_line(parameter: str, code: str) -> ShiftLine | None:
    """The clamp line `code` is in the form of `parameter`; None if it is no attempt at one;
    Refused if the form refuses other attempts (a Fanuc macro statement not in the form)."""
    form = CLAMPS[parameter]
    if not form.marks.search(code):
        return None
    for step, pattern in form.forms:
        match = pattern.fullmatch(code)
        if match:
            return ShiftLine(parameter, step, tuple(plain_decimal(parameter, text) for text in match.groups()))
    if form.refuse_others:
        raise Refused(f"a macro statement other than the hob-shift clamp: only {form.shape} is read, "
                      "any other variable, bracket, GOTO or WHILE cannot be verified")
    return None


class ShiftClamp(msgspec.Struct):
    """Where the walk is in the clamp's lines, and the interval they clamp the variable to."""
    parameter: str = "R11"
    at: int = 0
    low: float = 0.0
    high: float = 0.0

    @property
    def form(self) -> ClampForm:
        return CLAMPS[self.parameter]

    def take(self, line: ShiftLine) -> tuple[float, float] | None:
        """→ (lo, hi) at the move, the positions Y takes; Refused out of order or out of the interval."""
        if not self.at:
            self.parameter = line.parameter
        sequence = self.form.sequence
        if line.parameter != self.parameter or line.step != sequence[self.at]:
            raise Refused(f"the hob-shift clamp must read exactly {self.form.shape}, in this order")
        self.at = (self.at + 1) % len(sequence)
        return STEPS[line.step](self, *line.values)

    def interrupted(self) -> None:
        if self.at:
            raise Refused(f"the hob-shift clamp is incomplete: {self.form.shape} stand together, in this order")

    def _step(self, step: float) -> None:
        if step <= 0:
            raise Refused(f"the shift per part {step:g} must be above 0")

    def _test(self, low: float, high: float) -> None:
        if low > high:
            raise Refused(f"the clamp interval {low:g} … {high:g} is empty")
        self.low, self.high = low, high

    def _reset(self, value: float) -> None:
        if not self.low <= value <= self.high:
            raise Refused(f"{self.parameter}={value:g} lies outside the interval {self.low:g} … {self.high:g} "
                          "the clamp keeps it in")

    def _below(self, low: float, reset: float) -> None:
        """Fanuc: below the interval the hob starts again at its low end, lo itself."""
        if reset != low:
            raise Refused(f"IF [{self.parameter} LT {low:g}] sets {self.parameter}={reset:g}: the clamp starts "
                          f"the hob again at the low end, {self.parameter}={low:g}")
        self.low = low

    def _above(self, high: float, reset: float) -> None:
        """Fanuc: above the interval too, to the same low end; then lo <= #500 <= hi."""
        if reset != self.low:
            raise Refused(f"IF [{self.parameter} GT {high:g}] sets {self.parameter}={reset:g}: the clamp starts "
                          f"the hob again at the low end, {self.parameter}={self.low:g}")
        self._test(self.low, high)

    def _end(self) -> None:
        return None

    def _move(self) -> tuple[float, float]:
        return self.low, self.high


# each step takes the values its form captures
STEPS: dict[str, Callable[..., tuple[float, float] | None]] = {
    "step": ShiftClamp._step, "test": ShiftClamp._test, "reset": ShiftClamp._reset,
    "below": ShiftClamp._below, "above": ShiftClamp._above,
    "end": ShiftClamp._end, "move": ShiftClamp._move}
