"""The words and parameter settings of one LinuxCNC line, their values read with the parameters
as they stand before the line (LinuxCNC: a setting takes effect after every value of its line
is read, docs/reference/linuxcnc-lathe.md §2). G and M may stand several times, once per modal
group; every other letter once. Letters of axes the lathe does not have are refused, but for the
words of a G70-G72 (g-code.adoc G71: U/W on the cycle's line; U/W incremental X/Z and A/C a
fillet/chamfer in its profile's lines, read with `profile`)."""
from __future__ import annotations

from collections.abc import Callable

import msgspec

from ..refusals import Refused
from .linuxcnc_values import Values

LETTERS = frozenset("dfghiijkklmpqrstxze")          # the words a LinuxCNC lathe program uses
OTHER_AXES = frozenset("abcuvwy")                    # axes a two-axis lathe does not have
PROFILE_WORDS = frozenset("acuw")                    # G70-G72's own meaning of these letters
G7X = ("70", "71", "71.1", "71.2", "72", "72.1", "72.2")


class Words(msgspec.Struct):
    codes: dict[str, list[float]] = msgspec.field(default_factory=lambda: {"g": [], "m": []})
    values: dict[str, float] = {}
    settings: list[tuple[str, float]] = []

    def g(self, *names: str) -> str | None:
        """The first of the line's G codes among `names` ("0", "33.1"), or None."""
        written = {f"{code:g}" for code in self.codes["g"]}
        return next((name for name in names if name in written), None)

    def has_m(self, code: int) -> bool:
        return float(code) in self.codes["m"]


def read_words(code: str, lookup: Callable[[str], float], defined: Callable[[str], bool],
               profile: bool = False) -> Words:
    reader, words = Values(code, lookup, defined), Words()
    while reader.at < len(code):
        letter = reader.peek()
        if letter == "#":
            key = reader.parameter()
            reader.expect("=")
            words.settings.append((key, reader.value()))
            continue
        reader.at += 1
        _word(letter, reader.value(), words)
    allowed = PROFILE_WORDS if profile else frozenset("uw") if words.g(*G7X) else frozenset()
    for letter in sorted(PROFILE_WORDS & words.values.keys() - allowed):
        name = letter.upper()
        raise Refused(f"{name}{words.values[letter]:g}: the lathe has no {name} axis (X and Z only)")
    return words


def _word(letter: str, value: float, words: Words) -> None:
    if letter in words.codes:
        if round(value * 10) != value * 10 or value < 0:
            raise Refused(f"{letter.upper()}{value:g} is not a {letter.upper()} code")
        words.codes[letter].append(value)
    elif letter in OTHER_AXES - PROFILE_WORDS:
        raise Refused(f"{letter.upper()}{value:g}: the lathe has no {letter.upper()} axis (X and Z only)")
    elif letter not in LETTERS | PROFILE_WORDS:
        raise Refused(f"{letter.upper()} is not a word of a LinuxCNC lathe program")
    elif letter in words.values:
        raise Refused(f"{letter.upper()} twice in one line")
    else:
        words.values[letter] = value
