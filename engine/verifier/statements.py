"""The electronic-gearbox statements of 840D hobbing (reference §A5), read argument by argument:
`EGDEF(C,B,1[,Z,1][,Y,1])` defines the coupling of the table C to the hob spindle B (and the
differential axes), `EGON(C,"FINE",B,z0,z2[,Z,num,den]…)` switches it on with the ratio z0/z2,
`EGOFS(C)` switches it off, `EGDEL(C)` deletes it. The ratio and the differential factors are
kept: with the spindle speed S and the feeds of Z and Y they give the table speed the machine
record bounds (reference §A5: n_C = (z0/z2)·n_B ± k_Y·v_Y ± k_Z·v_Z)."""
from __future__ import annotations

import re
from typing import ClassVar, Literal

import msgspec

from .numbers import plain_decimal, whole_number
from .refusals import Refused

STATEMENT = re.compile(r"([A-Z]+)\((.*)\)")
FOLLOWING_AXIS = "C"                 # the table follows
HOB_SPINDLE = "B"                    # the hob spindle leads, always first
LEADING_AXES = ("B", "Z", "Y")       # B; Z for the helical differential; Y for tangential feed
COUPLING_TYPES = ("0", "1")          # 0 actual value, 1 setpoint
# The block-change modes of EGON (reference §A5): "NOC" changes block at once, "COARSE" at coarse
# synchronism; the first cut would then start with the table not yet in step with the hob and cut
# the teeth out of phase. Only "FINE" (block change at fine synchronism) is accepted.
EG_MODES = ('"FINE"',)
EG_MODES_KNOWN = ('"NOC"', '"FINE"', '"COARSE"', '"IPOSTOP"')
RATIO_DIGITS = 4                     # teeth and starts: no gear has 10,000 teeth
# Degrees of C per mm of Z or Y: 360/lead (reference §B9, §B10), 0.494 °/mm for m 2, z 30,
# β 15°. A full table turn per mm of travel is a lead of 1 mm, which no hobbed gear has.
MAX_DIFFERENTIAL = 360.0


class GearBox(msgspec.Struct, frozen=True):
    """A Fanuc electronic-gear-box start as read (engine.verifier.synchronisation), its terms with
    their signs: the simulation turns them into the coupling (engine.simulation.hobbing.fanuc_egb)
    and its findings quote the words as written."""
    teeth: int                   # T (G81) or R (G81.4): the gear's teeth
    threads: int                 # L, signed: its sign gives the table's direction
    module: float | None         # Q, mm; None: the block gives neither Q nor P
    helix: float | None          # P, degrees, signed
    teeth_word: str              # "T19", as written
    threads_word: str            # "L-1"
    helix_words: str = ""        # "Q3. P-15.", or ""

    @property
    def ratio_words(self) -> str:
        return f"{self.threads_word} {self.teeth_word}"


class Statement(msgspec.Struct, frozen=True):
    """A coupling statement (EGDEF, EGON, EGOFS, EGDEL; Fanuc G81/G80, engine.verifier.synchronisation)
    as read: its leading axes, ratio and factors, and a Fanuc start's signed terms."""
    kind: ClassVar[Literal["statement"]] = "statement"
    name: str
    leading: tuple[str, ...] = ()    # leading axes, in order
    ratio: float | None = None       # |z0/z2| of the hob spindle (EGON; Fanuc G81 |L|/T)
    factors: tuple[tuple[str, float], ...] = ()   # (axis, |degrees of C per mm|) of Z and Y (EGON)
    gear_box: GearBox | None = None  # Fanuc G81/G81.4: T, L, Q, P with their signs


def read_statement(name: str, arguments: str) -> Statement:
    return READERS[name](name, arguments.split(","))


def _following(name: str, arguments: list[str]) -> None:
    if arguments[0] != FOLLOWING_AXIS:
        raise Refused(f"{name}: the following axis must be {FOLLOWING_AXIS} (the table), not {arguments[0]!r}")


def _leading(name: str, axes: list[str]) -> tuple[str, ...]:
    if not axes or axes[0] != HOB_SPINDLE or len(set(axes)) != len(axes) or not set(axes) <= set(LEADING_AXES):
        raise Refused(f"{name}: the leading axes must be {HOB_SPINDLE} first, then Z and/or Y once each, "
                      f"not {','.join(axes)}")
    return tuple(axes)


def _egdef(name: str, arguments: list[str]) -> Statement:
    _following(name, arguments)
    pairs = arguments[1:]
    if len(pairs) % 2 or any(kind not in COUPLING_TYPES for kind in pairs[1::2]):
        raise Refused(f"{name}: after {FOLLOWING_AXIS} come pairs of a leading axis and a coupling type 0 or 1")
    return Statement(name, _leading(name, pairs[0::2]))


def _egon(name: str, arguments: list[str]) -> Statement:
    _following(name, arguments)
    if len(arguments) < 2 or arguments[1] not in EG_MODES:
        given = f", not {arguments[1]}, which goes on before the table is in step" \
            if len(arguments) >= 2 and arguments[1] in EG_MODES_KNOWN else ""
        raise Refused(f"{name}: the block-change mode must be \"FINE\" (wait for fine synchronism before the next "
                      f"block, reference §A5){given}")
    triples = arguments[2:]
    if not triples or len(triples) % 3:
        raise Refused(f"{name}: after the mode come triples of a leading axis, numerator and denominator")
    leading = _leading(name, triples[0::3])
    ratio = _hob_ratio(name, triples[1], triples[2])
    return Statement(name, leading, ratio, _differential_factors(name, triples[3:]))


def _hob_ratio(name: str, numerator: str, denominator: str) -> float:
    """z0/z2 of the hob spindle: whole numbers, the starts signed, the teeth above 0."""
    starts = whole_number(f"{name} hob starts ", numerator, RATIO_DIGITS)
    teeth = whole_number(f"{name} teeth ", denominator, RATIO_DIGITS)
    if starts == 0 or teeth <= 0 or denominator[0] in "+-":
        raise Refused(f"{name}: the hob ratio {numerator}/{denominator} must be whole numbers "
                      "±starts/teeth, neither 0")
    return abs(starts / teeth)


def _differential_factors(name: str, triples: list[str]) -> tuple[tuple[str, float], ...]:
    """Z and Y factors (degrees of C per mm): plain decimals over a denominator that is not 0,
    at most MAX_DIFFERENTIAL in size."""
    factors = []
    for axis, numerator, denominator in zip(triples[0::3], triples[1::3], triples[2::3]):
        top = plain_decimal(f"{name} {axis} factor ", numerator)
        bottom = plain_decimal(f"{name} {axis} denominator ", denominator)
        if bottom == 0:
            raise Refused(f"{name}: the {axis} factor's denominator is 0")
        factor = abs(top / bottom)
        if factor > MAX_DIFFERENTIAL:
            raise Refused(f"{name}: the {axis} factor {numerator}/{denominator} is {factor:.6g}°/mm, above "
                          f"{MAX_DIFFERENTIAL:g}°/mm (a lead shorter than 1 mm): no hobbed gear has it")
        factors.append((axis, factor))
    return tuple(factors)


def _off(name: str, arguments: list[str]) -> Statement:
    if arguments != [FOLLOWING_AXIS]:
        raise Refused(f"{name} takes the following axis only: {name}({FOLLOWING_AXIS})")
    return Statement(name)


READERS = {"EGDEF": _egdef, "EGON": _egon, "EGOFS": _off, "EGDEL": _off}
