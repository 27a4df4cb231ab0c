"""The one use of an R-parameter the verifier reads: the hob shift per part of the hobbing
templates. R11 keeps the shift from part to part on the control, so its value is unknown here;
the five lines below clamp it, so after them R11 lies in [lo, hi]:

    R11=R11+<step>            ; the shift of this part
    IF (R11<lo) OR (R11>hi)
    R11=<reset>               ; lo <= reset <= hi
    ENDIF
    G0 Y=R11

The move is checked at both ends of that interval. Exactly these lines, in this order, and
nothing between them; any other R-parameter use is refused (engine.verifier.numbers)."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, ClassVar, Literal

import msgspec

from .numbers import plain_decimal
from .refusals import Refused

if TYPE_CHECKING:
    from collections.abc import Callable

PARAMETER = "R11"
UNSIGNED = r"(\d+(?:\.\d*)?|\.\d+)"
DECIMAL = r"([-+]?(?:\d+(?:\.\d*)?|\.\d+))"
FORMS = (
    ("step", re.compile(rf"{PARAMETER}={PARAMETER}\+{UNSIGNED}")),
    ("test", re.compile(rf"IF \({PARAMETER}<{DECIMAL}\) OR \({PARAMETER}>{DECIMAL}\)")),
    ("reset", re.compile(rf"{PARAMETER}={DECIMAL}")),
    ("end", re.compile(r"ENDIF")),
    ("move", re.compile(rf"G0 Y={PARAMETER}")),
)
SEQUENCE = tuple(step for step, _ in FORMS)
SHAPE = f"{PARAMETER}=R11+step, IF ({PARAMETER}<lo) OR ({PARAMETER}>hi), {PARAMETER}=lo…hi, ENDIF, G0 Y={PARAMETER}"


class ShiftLine(msgspec.Struct, frozen=True):
    """One of the hob-shift lines of SHAPE as read: which (step) and the numbers it gives."""
    kind: ClassVar[Literal["shift"]] = "shift"
    step: str
    values: tuple[float, ...]


def read_shift_line(code: str) -> ShiftLine | None:
    if PARAMETER not in code and "IF" not in code:
        return None
    for step, pattern in FORMS:
        match = pattern.fullmatch(code)
        if match:
            return ShiftLine(step, tuple(plain_decimal(PARAMETER, text) for text in match.groups()))
    return None


class ShiftClamp(msgspec.Struct):
    """Where the walk is in the five lines, and the interval they clamp R11 to."""
    at: int = 0
    low: float = 0.0
    high: float = 0.0

    def take(self, line: ShiftLine) -> tuple[float, float] | None:
        """→ (lo, hi) at the move, the positions Y takes; Refused out of order or out of the interval."""
        if line.step != SEQUENCE[self.at]:
            raise Refused(f"the hob-shift clamp must read exactly {SHAPE}, in this order")
        self.at = (self.at + 1) % len(SEQUENCE)
        return STEPS[line.step](self, *line.values)

    def interrupted(self) -> None:
        if self.at:
            raise Refused(f"the hob-shift clamp is incomplete: {SHAPE} stand together, in this order")

    def _step(self, step: float) -> None:
        if step <= 0:
            raise Refused(f"the shift per part {step:g} must be above 0")

    def _test(self, low: float, high: float) -> None:
        if low > high:
            raise Refused(f"the clamp interval {low:g} … {high:g} is empty")
        self.low, self.high = low, high

    def _reset(self, value: float) -> None:
        if not self.low <= value <= self.high:
            raise Refused(f"{PARAMETER}={value:g} lies outside the interval {self.low:g} … {self.high:g} "
                          "the clamp keeps it in")

    def _end(self) -> None:
        return None

    def _move(self) -> tuple[float, float]:
        return self.low, self.high


# each step takes the values its form captures
STEPS: dict[str, Callable[..., tuple[float, float] | None]] = {
    "step": ShiftClamp._step, "test": ShiftClamp._test, "reset": ShiftClamp._reset,
    "end": ShiftClamp._end, "move": ShiftClamp._move}
