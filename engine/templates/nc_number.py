"""A number of an imported NC program written with the value given (issue 27): never rounded to
the decimals the file happened to write. An imported row prints a bound word as the f-string
field `{feed:~#.000}` (a format spec `~` and the style: the evaluator calls nc_number for it;
`{nc_number(feed, '#.000')}` is the same as a call, for templates written by hand, but costs half
as much again to compile, and an imported program compiles a row per line): the value's own
digits (its shortest exact decimal: the float 0.025 is 0.025, not 0.0250000000000000013…), in the
style of the number as the file wrote it:

* the value the file had gives the file's spelling back exactly (`0.010` stays `0.010`), so the
  import comes back byte for byte;
* another value keeps at least the file's decimals (`0.010` style: 0.02 → `0.020`) and takes as
  many more as its digits need (0.025 → `0.025`, 0.0125 → `0.0125`, never `0.013`);
* a trailing point stays where the file wrote one (`F31.` style: 31.25 → `31.25`, 20 → `20.`);
  leading zeros (`-00500`), an explicit `+` and a number with no digit before the point (`.4`)
  keep their style.

The style is the shape of the file's number, not its value, so that the members of a family
(the same program in mm and in inch) share their rows: `#.000` (digits, three decimals),
`#.` (a trailing point), `00000` (zero-padded to five characters, the sign included: a column of a
fixed-column tape keeps its width), `+#` (an explicit plus), `.0`
(no digit before the point). A number written in its own style gives its spelling back, so the
imported file comes back byte for byte (engine.library.nc_rows keeps literal the rare number
that would not).

A value a control cannot read exactly is refused, never rounded: more than MAX_SIGNIFICANT
significant digits (a Fanuc word holds 8 digits; the 840D's input format of a position or feed is
no wider; a style with more digits allows as many), or a value that is no finite number."""
from __future__ import annotations

import math
import re
from decimal import Decimal

MAX_SIGNIFICANT = 8   # digits of one NC word a Fanuc (8-digit input) or 840D control reads
_STYLE = re.compile(r"(\+?)(#|0*)(\.?)(0*)")
_SPELLING = re.compile(r"([+-]?)([0-9]*)(\.?)([0-9]*)")


def style_of(spelling: str) -> str:
    """The shape of a number as written: `0.010` → `#.000`, `-00500` → `00000`, `+.5` → `+.0`."""
    spelled = _SPELLING.fullmatch(spelling)
    if spelled is None or not any(character.isdigit() for character in spelling):
        raise ValueError(f"{spelling!r} is not the spelling of a number")
    sign, integer, point, fraction = spelled.groups()
    padded = len(integer) > 1 and integer.startswith("0")
    whole = "0" * len(sign + integer) if padded else ("#" if integer else "")   # width with the sign: a column
    return f"{'+' if sign == '+' else ''}{whole}{point}{'0' * len(fraction)}"


def written_number(value, style: str) -> str:
    """`value` written as an NC number in `style` (style_of a number as a file wrote it)."""
    exact = exact_decimal(value)
    shaped = _STYLE.fullmatch(style)
    if shaped is None:
        raise ValueError(f"{style!r} is not the style of a number (please report this row)")
    plus, whole, point, fraction = shaped.groups()
    _check_digits(exact, len(whole.replace("#", "")) + len(fraction))
    return _written(exact, plus, whole, point, len(fraction))


def exact_decimal(value) -> Decimal:
    """The shortest decimal that is exactly the value (repr of a float), or ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, Decimal)):
        raise ValueError(f"{value!r} is not a number: a bound NC word is written from a number")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{value!r} is no number a program can write; give a finite value")
    exact = Decimal(repr(value)) if isinstance(value, float) else Decimal(value)
    if not exact.is_finite():
        raise ValueError(f"{value!r} is no number a program can write; give a finite value")
    return exact


def _significant(number: Decimal) -> int:
    """Significant digits of a decimal, trailing zeros of the integer part counted (1200 has 4)."""
    if not number:
        return 1
    digits = number.normalize().as_tuple()
    return len(digits.digits) + max(int(digits.exponent), 0)


def _check_digits(exact: Decimal, style_digits: int) -> None:
    allowed = max(MAX_SIGNIFICANT, style_digits)
    if _significant(exact) > allowed:
        raise ValueError(f"{exact} has {_significant(exact)} significant digits, more than the {allowed} an NC word "
                         "holds: it cannot be written exactly, and it is not rounded; give the value to fewer digits")


def _written(exact: Decimal, plus: str, whole_style: str, point: str, decimals: int) -> str:
    """The digits of `exact`, at least `decimals` after the point, in the style's sign, padding and point."""
    places = max(decimals, -int(exact.normalize().as_tuple().exponent), 0)
    whole, _, fraction = f"{abs(exact):.{places}f}".partition(".")
    if not whole_style and whole == "0" and (fraction or point):
        whole = ""                                   # `.4` style: no digit before the point
    signed = "-" if exact < 0 else plus
    if whole_style.startswith("0"):                  # `-00500` style: zero-padded to the column's width
        whole = whole.zfill(len(whole_style) - len(signed))
    if fraction:
        return f"{signed}{whole}.{fraction}"
    return f"{signed}{whole}{'.' if point else ''}"
