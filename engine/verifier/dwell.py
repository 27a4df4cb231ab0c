"""A dwell: `G4 <word><time>` holds the axes for a time and moves nothing. Its block is the
command alone (the 840D's G4 F<s>, reference sinumerik-lathe §S6; the Fanuc forms of reference
fanuc-egb.md §F8), and its word is a time, not a feed or a position: on a Fanuc-type control
`G04 X2.5` dwells 2.5 s, it does not move X. So a dwell block is read here, word by word with
the dialect's dwell words (grammar.DwellWord), before the block reader would take X for an axis:

* one time word, once: `G04` alone states no time, and `G04 X1. P500` states it twice (which
  one the control takes is not the verifier's to guess);
* its decimal point as the word needs it: Fanuc's X without one is read in the least input
  increment (X2 is 0.002 s under IS-B, 0.0002 s under IS-C), P with one is not a whole number
  of milliseconds;
* above 0 s and at most MAX_DWELL seconds."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

from .numbers import plain_decimal, whole_number
from .refusals import Refused

if TYPE_CHECKING:
    from .grammar import Dialect, DwellWord

DWELL_CODE = re.compile(r"G0{0,2}4")       # G4, G04, G004: what the G code reader reads as 4
WORD = re.compile(r"([A-Z]+)(=?)(.*)")
MAX_DWELL = 99999.999       # s: the largest X of a Fanuc dwell under IS-B (fanuc-egb.md §F8)
WHOLE_DIGITS = 8            # P: at most 99999999 ms (fanuc-egb.md §F8)


def is_dwell(tokens: list[str]) -> bool:
    return any(DWELL_CODE.fullmatch(token) for token in tokens)


def read_dwell(dialect: Dialect, tokens: list[str]) -> float:
    """The seconds a dwell block holds the axes for, or Refused naming what is wrong."""
    code = next(token for token in tokens if DWELL_CODE.fullmatch(token))
    dialect.code_group("G", 4)         # a dialect without G4 refuses it by name
    words = {word.address: word for word in dialect.dwell_words}
    given = [_word(code, words, token) for token in tokens if token is not code]
    names = " or ".join(words)
    if not given:
        raise Refused(f"{code} without its {names}: a dwell states its time (without one the block dwells for no "
                      "time the program says)")
    if len(given) > 1:
        raise Refused(f"{code} with {' and '.join(f'{word.address}{text}' for word, text in given)}: "
                      "a dwell states its time once")
    return _seconds(dialect, *given[0])


def _word(code: str, words: dict[str, DwellWord], token: str) -> tuple[DwellWord, str]:
    match = WORD.fullmatch(token)
    address, equals, text = match.groups() if match else ("", "", token)
    if address not in words or equals:
        raise Refused(f"a {code} block (dwell) holds only {', '.join(words)}, not {token}: the dwell's time alone")
    return words[address], text


def _seconds(dialect: Dialect, word: DwellWord, text: str) -> float:
    """The dwell's seconds: above 0 and at most MAX_DWELL."""
    value = _value(dialect, word, text) * word.seconds
    if value <= 0:
        raise Refused(f"{word.address}{text} must be above 0: a dwell of {value:g} s")
    if value > MAX_DWELL:
        raise Refused(f"{word.address}{text}: a dwell of {value:g} s, above the {MAX_DWELL:.3f} s a control takes")
    return value


def _value(dialect: Dialect, word: DwellWord, text: str) -> float:
    """The number as written, with the decimal point the word needs (or must not have)."""
    shown = f"{word.address}{text}"
    point = word.point if word.point is not None else word.address in dialect.point_required
    if point and "." not in text:
        raise Refused(f"{shown} needs a decimal point: without one the control reads a dwell's {word.address} in its "
                      f"least input increment ({word.address}2 is 0.002 s, or 0.0002 s), not in seconds; "
                      f"write {shown}.")
    if word.point is not False:
        return plain_decimal(word.address, text)
    if "." in text or text[:1] in "+-":
        raise Refused(f"{shown}: {word.address} is a whole number of milliseconds, without a sign or a decimal "
                      "point (a Fanuc alarms or reads it otherwise); or write the seconds as X with its point")
    return whole_number(word.address, text, WHOLE_DIGITS)
