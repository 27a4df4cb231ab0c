"""Values as the verifier reads them: a plain decimal number (an optional sign, digits, an
optional point) and nothing else. A control evaluates address expressions, R-parameters,
IC/AC, indirect axes and exponents at run time; the verifier cannot, so it refuses them and
says which of them it found."""
from __future__ import annotations

import math
import re

from .refusals import Refused

PLAIN_DECIMAL = re.compile(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)")

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
        raise Refused(f"{word}{text}: {why_not_plain(text)}")
    value = float(text)
    if not math.isfinite(value):
        raise Refused(f"{word}{text}: more digits than any limit (not a finite number)")
    return value


def digits(word: str, text: str, count: range, what: str) -> int:
    """An unsigned integer of `count` digits (codes, tool numbers)."""
    if not (text.isdecimal() and text.isascii() and len(text) in count):
        reason = why_not_plain(text) if not text.isdecimal() else f"{len(text)} digits"
        raise Refused(f"{word}{text} is not {what} ({reason})")
    return int(text)
