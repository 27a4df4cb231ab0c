"""The electronic-gearbox statements of 840D hobbing (reference §A5), read argument by argument:
`EGDEF(C,B,1[,Z,1][,Y,1])` defines the coupling of the table C to the hob spindle B (and the
differential axes), `EGON(C,"FINE",B,z0,z2[,Z,num,den]…)` switches it on with the ratio z0/z2,
`EGOFS(C)` switches it off, `EGDEL(C)` deletes it. The ratio is kept: with the spindle speed S it
gives the table speed the machine record bounds."""
from __future__ import annotations

import re
from dataclasses import dataclass

from .numbers import plain_decimal
from .refusals import Refused

STATEMENT = re.compile(r"([A-Z]+)\((.*)\)")
FOLLOWING_AXIS = "C"                 # the table follows
HOB_SPINDLE = "B"                    # the hob spindle leads, always first
LEADING_AXES = ("B", "Z", "Y")       # B; Z for the helical differential; Y for tangential feed
COUPLING_TYPES = ("0", "1")          # 0 actual value, 1 setpoint
EG_MODES = ('"NOC"', '"FINE"', '"COARSE"', '"IPOSTOP"')
INTEGER = re.compile(r"[-+]?\d+")


@dataclass(frozen=True, slots=True)
class Statement:
    kind = "statement"
    name: str
    leading: tuple = ()              # leading axes, in order
    ratio: float | None = None       # |z0/z2| of the hob spindle (EGON)


def read_statement(name: str, arguments: str) -> Statement:
    return READERS[name](name, arguments.split(","))


def _following(name: str, arguments: list) -> None:
    if arguments[0] != FOLLOWING_AXIS:
        raise Refused(f"{name}: the following axis must be {FOLLOWING_AXIS} (the table), not {arguments[0]!r}")


def _leading(name: str, axes: list) -> tuple:
    if not axes or axes[0] != HOB_SPINDLE or len(set(axes)) != len(axes) or not set(axes) <= set(LEADING_AXES):
        raise Refused(f"{name}: the leading axes must be {HOB_SPINDLE} first, then Z and/or Y once each, "
                      f"not {','.join(axes)}")
    return tuple(axes)


def _egdef(name: str, arguments: list) -> Statement:
    _following(name, arguments)
    pairs = arguments[1:]
    if len(pairs) % 2 or any(kind not in COUPLING_TYPES for kind in pairs[1::2]):
        raise Refused(f"{name}: after {FOLLOWING_AXIS} come pairs of a leading axis and a coupling type 0 or 1")
    return Statement(name, _leading(name, pairs[0::2]))


def _egon(name: str, arguments: list) -> Statement:
    _following(name, arguments)
    if len(arguments) < 2 or arguments[1] not in EG_MODES:
        raise Refused(f"{name}: the block-change mode must be one of {', '.join(EG_MODES)}")
    triples = arguments[2:]
    if not triples or len(triples) % 3:
        raise Refused(f"{name}: after the mode come triples of a leading axis, numerator and denominator")
    leading = _leading(name, triples[0::3])
    ratio = _hob_ratio(name, triples[1], triples[2])
    _differential_factors(name, triples[3:])
    return Statement(name, leading, ratio)


def _hob_ratio(name: str, numerator: str, denominator: str) -> float:
    """z0/z2 of the hob spindle: whole numbers, the starts signed, the teeth above 0."""
    if not (INTEGER.fullmatch(numerator) and denominator.isdecimal() and denominator.isascii()
            and int(numerator) != 0 and int(denominator) > 0):
        raise Refused(f"{name}: the hob ratio {numerator}/{denominator} must be whole numbers "
                      "±starts/teeth, neither 0")
    return abs(int(numerator) / int(denominator))


def _differential_factors(name: str, triples: list) -> None:
    """Z and Y factors (degrees of C per mm): plain decimals over a denominator that is not 0."""
    for axis, numerator, denominator in zip(triples[0::3], triples[1::3], triples[2::3]):
        plain_decimal(f"{name} {axis} factor ", numerator)
        if plain_decimal(f"{name} {axis} denominator ", denominator) == 0:
            raise Refused(f"{name}: the {axis} factor's denominator is 0")


def _off(name: str, arguments: list) -> Statement:
    if arguments != [FOLLOWING_AXIS]:
        raise Refused(f"{name} takes the following axis only: {name}({FOLLOWING_AXIS})")
    return Statement(name)


READERS = {"EGDEF": _egdef, "EGON": _egon, "EGOFS": _off, "EGDEL": _off}
