"""Values as the verifier reads them: a plain decimal number (an optional sign, digits, an
optional point) and nothing else. A control evaluates address expressions, R-parameters,
IC/AC, indirect axes and exponents at run time; the verifier cannot, so it refuses them and
says which of them it found.

A number has at most MAX_DIGITS digits: no limit of these machines needs more (a micrometre
over a hundred kilometres), a control refuses a word longer than its input format, and a
number of hundreds of digits is no value at all, only a way to overflow a float. The digits
are counted before the text is converted, so no number the verifier reads can crash it."""
from __future__ import annotations

import math
import re

from .refusals import Refused

PLAIN_DECIMAL = re.compile(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)")
WHOLE = re.compile(r"[-+]?\d+")
MAX_DIGITS = 12

# Why a value is not plain: the first that matches names it (text upper-cased).
NOT_PLAIN = (
    (re.compile(r"\b(?:IC|AC|DC|ACP|ACN|CIC|CAC)\("), "IC(…)/AC(…) make the value incremental or "
                                                      "relative to a position the verifier cannot see"),
    (re.compile(r"\["), "an indirect address such as AX[…] names its axis at run time"),
    (re.compile(r"(?<![A-Z])R\d|\$"), "an R-parameter or system variable has its value only on the control"),
    (re.compile(r"INF|NAN"), "inf/nan is not a position, speed or feed"),
    (re.compile(r"[\d.]E"), "an exponent: controls read no exponent, and a plain decimal is required"),
    (re.compile(r".[-+*/()<>=]|^[*/()<>=]"), "an address expression: the verifier reads only "
                                             "plain decimal numbers"),
)


def why_not_plain(text: str, otherwise: str | None = "not a plain decimal number") -> str | None:
    upper = text.upper()
    for pattern, reason in NOT_PLAIN:
        if pattern.search(upper):
            return reason
    return otherwise


def plain_decimal(word: str, text: str) -> float:
    """The value of `text` (written after address `word`), or Refused with the reason."""
    if not PLAIN_DECIMAL.fullmatch(text):
        raise Refused(f"{word}{_cut(text)}: {why_not_plain(text)}")
    _check_length(word, text)
    value = float(text)
    if not math.isfinite(value):
        raise Refused(f"{word}{text}: more digits than any limit (not a finite number)")
    return value


def whole_number(word: str, text: str, digits_at_most: int) -> int:
    """A signed whole number of at most `digits_at_most` digits (teeth, starts), or Refused."""
    if not WHOLE.fullmatch(text):
        raise Refused(f"{word}{_cut(text)}: {why_not_plain(text, 'not a whole number')}")
    _check_length(word, text, digits_at_most)
    return int(text)


def digits(word: str, text: str, count: range, what: str) -> int:
    """An unsigned integer of `count` digits (codes, tool numbers)."""
    if not (text.isdecimal() and text.isascii() and len(text) in count):
        reason = why_not_plain(text) if not text.isdecimal() else f"{len(text)} digits"
        raise Refused(f"{word}{_cut(text)} is not {what} ({reason})")
    return int(text)


def _check_length(word: str, text: str, digits_at_most: int = MAX_DIGITS) -> None:
    count = sum(character.isdigit() for character in text)
    if count > digits_at_most:
        raise Refused(f"{word}{_cut(text)}: {count} digits, more than the {digits_at_most} a value of this "
                      "program may have")


def _cut(text: str) -> str:
    """A long number shown by its first digits (the whole of it would make the message a page)."""
    return text if len(text) <= 24 else f"{text[:20]}…"
