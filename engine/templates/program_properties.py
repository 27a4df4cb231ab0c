"""Numeric properties read from a program's lines, for the golden tests' expectations
(engine.templates.expectations): the values a DBA names in `template_test.expect`, such as
`last X`, `EGON ratio` or `count of G1`.

Each property gives a `Reading`: the value, the line it came from (1-based, and its text) and
the printed precision of the number, so an expectation's default tolerance is what the program
could print (half a unit in its last digit). Properties are looked up by their name through
the table PROPERTY_PATTERNS (rules as data): an unknown name is refused, never read as zero.
"""
from __future__ import annotations

import re

import msgspec

COMMENT = re.compile(r";.*$|(?<![A-Za-z0-9_])\([^()]*\)")   # 840D `; …` and ISO `( … )` comments (not calls)
WORD = re.compile(r"(?<![A-Za-z_$0-9.])([A-Z])=?(-?(?:\d+\.?\d*|\.\d+))(?![A-Za-z_(])")
EGON_CALL = re.compile(r"\bEGON\s*\(([^)]*)\)")
MOTIONS = {0: "G0", 1: "G1", 2: "G2", 3: "G3"}   # the modal motion group an address value is filtered by
LIMIT_CODES = {25.0, 26.0}   # G25/G26 X… Y… Z… S…: working-area and speed limits, not positions (hobbing.md §A4)


class Reading(msgspec.Struct, frozen=True):
    """A value read from the program, where it was, and how finely the program printed it."""
    value: float
    line_number: int | None = None   # 1-based; None for a count over the whole program
    text: str = ""
    printed_step: float = 0.0        # one unit in the last printed digit (0: exact, e.g. a count)

    def where(self) -> str:
        return f" (line {self.line_number}: {self.text})" if self.line_number is not None else ""


def decimals_step(number: str) -> float:
    """One unit in the last digit of a printed number: 0.001 for `51.500`, 1 for `19`."""
    return 10.0 ** -len(number.split(".")[1]) if "." in number else 1.0


def words(line: str) -> list[tuple[str, str]]:
    """The address words of a block (letter, printed number), comments left out."""
    return WORD.findall(COMMENT.sub("", line))


class AddressValue(msgspec.Struct, frozen=True):
    """The values of one address over the blocks that position (G25/G26 limits left out)."""
    address: str
    motion: str | None       # only blocks in this modal motion (G0, G1, …); None: any block

    def readings(self, lines: list[str]) -> list[Reading]:
        found, motion = [], None
        for number, line in enumerate(lines, 1):
            block = words(line)
            motion = _motion(block, motion)
            if self.motion is not None and motion != self.motion or _sets_limits(block):
                continue
            found += [Reading(float(v), number, line, decimals_step(v)) for a, v in block if a == self.address]
        return found


def _motion(block: list[tuple[str, str]], before: str | None) -> str | None:
    """The modal motion (G0…G3) after the block."""
    return next((MOTIONS[int(float(v))] for a, v in reversed(block) if a == "G" and float(v) in MOTIONS), before)


def _sets_limits(block: list[tuple[str, str]]) -> bool:
    return any(a == "G" and float(v) in LIMIT_CODES for a, v in block)


class EgonFactor(msgspec.Struct, frozen=True):
    """The coupling factor Zi/Ni of one leading axis in an EGON block (ratio: the B axis)."""
    axis: str

    def readings(self, lines: list[str]) -> list[Reading]:
        found = []
        for number, line in enumerate(lines, 1):
            for call in EGON_CALL.findall(COMMENT.sub("", line)):
                reading = _egon_factor(call, self.axis, number, line)
                if reading is not None:
                    found.append(reading)
        return found


def _egon_factor(call: str, axis: str, number: int, line: str) -> Reading | None:
    """EGON(FA, "mode", LA1, Z1, N1, LA2, Z2, N2, …): the factor of leading axis `axis`."""
    arguments = [argument.strip() for argument in call.split(",")]
    for index in range(2, len(arguments) - 2, 3):
        if arguments[index] == axis:
            numerator, denominator = arguments[index + 1], arguments[index + 2]
            try:
                value = float(numerator) / float(denominator)
            except (ValueError, ZeroDivisionError):
                return None
            step = decimals_step(numerator) / abs(float(denominator)) if "." in numerator else 0.0
            return Reading(value, number, line, step)
    return None


class SlopeXZ(msgspec.Struct, frozen=True):
    """dX/dZ of the last feed block (G1) that moves X and Z together (a taper's cone): absolute
    positions followed block by block."""

    def readings(self, lines: list[str]) -> list[Reading]:
        found, motion = [], None
        position: dict[str, float] = {}
        for number, line in enumerate(lines, 1):
            block = words(line)
            motion = _motion(block, motion)
            moved = {a: (float(v), decimals_step(v)) for a, v in block if a in "XZ"}
            if motion == "G1" and len(moved) == 2 and {"X", "Z"} <= position.keys() and moved["Z"][0] != position["Z"]:
                slope = (moved["X"][0] - position["X"]) / (moved["Z"][0] - position["Z"])
                step = 2 * max(moved["X"][1], moved["Z"][1]) / abs(moved["Z"][0] - position["Z"])
                found.append(Reading(slope, number, line, step))
            position.update({a: value for a, (value, _) in moved.items()})
        return found


class WordCount(msgspec.Struct, frozen=True):
    """Blocks holding the word (G1 counts G01 too: the number is compared, not the text)."""
    address: str
    number: float

    def readings(self, lines: list[str]) -> list[Reading]:
        count = sum(any(a == self.address and float(v) == self.number for a, v in words(line)) for line in lines)
        return [Reading(float(count))]


class LineCount(msgspec.Struct, frozen=True):
    def readings(self, lines: list[str]) -> list[Reading]:
        return [Reading(float(len(lines)))]


# Which reading of a property's list: first, last, smallest, largest.
PICKS = {"first": lambda r: r[0], "last": lambda r: r[-1],
         "min": lambda r: min(r, key=lambda x: x.value), "max": lambda r: max(r, key=lambda x: x.value)}

# Property name (regular expression) → the reader it makes. The first match wins.
PROPERTY_PATTERNS = (
    (r"(?:(first|last) )?EGON ratio", lambda m: (m.group(1) or "first", EgonFactor("B"))),
    (r"(?:(first|last) )?EGON ([A-Z]) factor", lambda m: (m.group(1) or "first", EgonFactor(m.group(2)))),
    (r"(first|last|min|max) (?:(G[0-3]) )?([A-Z])", lambda m: (m.group(1), AddressValue(m.group(3), m.group(2)))),
    (r"(?:(first|last) )?XZ slope", lambda m: (m.group(1) or "last", SlopeXZ())),
    (r"count of ([A-Z])(-?\d+(?:\.\d*)?)", lambda m: ("first", WordCount(m.group(1), float(m.group(2))))),
    (r"line count", lambda m: ("first", LineCount())),
)


class UnknownProperty(ValueError):
    """A property name no row of PROPERTY_PATTERNS reads."""


def property_reader(name: str):
    """(pick, reader) for a property name, or UnknownProperty."""
    normal = " ".join(name.split())
    for pattern, make in PROPERTY_PATTERNS:
        match = re.fullmatch(pattern, normal)
        if match:
            return make(match)
    raise UnknownProperty(f"unknown property {name!r} (known: EGON ratio, EGON <axis> factor, "
                          "first|last|min|max [G0|G1] <address>, XZ slope, count of <word>, line count)")


def read_property(name: str, lines: list[str]) -> Reading | None:
    """The property's value in the program, or None if the program has none (no such word)."""
    pick, reader = property_reader(name)
    found = reader.readings(lines)
    return PICKS[pick](found) if found else None
