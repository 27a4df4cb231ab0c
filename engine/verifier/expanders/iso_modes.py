"""What an ISO lathe program has set so far, as the expander follows it (issue 27): units (G20
inch is converted ×25.4), the frame (G50 X/Z shifts it), the position, the modal motion, the feed
mode and feed, the spindle (G97 r/min, or G96 constant surface speed bounded by its clamp G50 S),
the cycle words a first G71/G72/G73/G74/G75/G76 block sets, and the end."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import msgspec

from ..grammar import POINT_REASON

if TYPE_CHECKING:
    from ...machines.records import Machine

INCH = 25.4
# A Fanuc-type control with decimal-point input type I reads these without a point in its least
# input increment (X114 is 0.114 mm); a zero is the same either way.
POINT_WORDS = frozenset({"X", "Z", "U", "W", "R", "I", "K", "F"})


def check_points(words: list[tuple[str, str]], decimal_point_input: str = "increment") -> list[tuple[str, str]]:
    """The words as the control reads them: under pocket-calculator input (machine record
    decimal_point_input 'calculator', Fanuc parameter 3401#0 DPI = 1) X118 is 118 mm, written X118.;
    under increment input (type I) ValueError for such a word (but a zero): it would be 0.118 mm."""
    if decimal_point_input == "calculator":
        return [(letter, _pointed(text) if letter in POINT_WORDS else text) for letter, text in words]
    for letter, text in words:
        if letter in POINT_WORDS and "." not in text and float(text) != 0:
            raise ValueError(f"{letter}{text} {POINT_REASON}; write {letter}{text}.")
    return words


def _pointed(text: str) -> str:
    return text if "." in text else text + "."


def arc_radius(centre: tuple[float, float], start: tuple[float, float], end: tuple[float, float],
               clockwise: bool) -> float:
    """The R of an arc given by its centre I/K (radius values, from the start point; x diameters):
    negative when the arc sweeps more than half a turn (the ISO convention for R)."""
    i, k = centre
    cx, cz = start[0] / 2 + i, start[1] + k
    a0 = math.atan2(start[0] / 2 - cx, start[1] - cz)
    a1 = math.atan2(end[0] / 2 - cx, end[1] - cz)
    sweep = (a1 - a0) % (2 * math.pi)
    if clockwise:
        sweep = 2 * math.pi - sweep if sweep else 0.0
    radius = math.hypot(i, k)
    return -radius if sweep > math.pi + 1e-9 else radius


class Modes(msgspec.Struct):
    machine: Machine
    scale: float = 1.0                 # mm per program unit: 25.4 under G20
    x: float | None = None             # the tool's position in the frame the travel is stated in (mm)
    z: float | None = None
    shift_x: float = 0.0               # G50 X/Z: frame = program position + shift
    shift_z: float = 0.0
    motion: int | None = None          # the modal G0/G1/G2/G3/G32
    per_rev: bool | None = None        # G99 feed per revolution, G98 per minute, None unstated
    feed: float | None = None          # F as programmed (program units per rev or per min)
    css: bool = False                  # G96: S is a surface speed, the spindle turns up to the clamp
    clamp: float | None = None         # G50 S, r/min
    speed: float | None = None         # G97 S, r/min
    ended: bool = False
    tool: int | None = None
    cut_box: tuple[float, float] | None = None     # the largest X and Z any cut reached so far
    cycle: dict[str, float] = {}   # words a first cycle block set ("G71U": Δd …)
    absolute_stated: bool = False

    def length(self, text: str) -> float:
        return float(text) * self.scale

    def absolute(self, axis: str, text: str) -> float:
        return self.length(text) + (self.shift_x if axis == "X" else self.shift_z)

    def worst_speed(self) -> float | None:
        """The fastest the spindle may turn now, r/min: the clamp under G96, S under G97."""
        return self.clamp if self.css else self.speed

    def feed_per_minute(self, feed: float) -> float | None:
        """F as mm/min: per revolution × the worst-case speed under G99; None if no speed is known."""
        if not self.per_rev:
            return feed * self.scale
        speed = self.worst_speed()
        return None if speed is None else feed * self.scale * speed

    def cut(self, x: float, z: float) -> None:
        box = self.cut_box or (x, z)
        self.cut_box = (max(box[0], x), max(box[1], z))
