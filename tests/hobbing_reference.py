"""An independent reader of hobbing programs and the reference's numbers, for acceptance tests.

Shares no code with engine.verifier, engine.hobbing or tests/nc_reader.py: the tests of
issue 14 must check the engine's programs against the reference (docs/reference/hobbing.md
§A5, §A7, §B, §C and design notes §7), not against the engine's own idea of them.

Reader: `read(text) -> Nc`. Each block has its G and M codes, its address words (`X12.5`, `A=-1.7`,
`Y=R11` keeps the text 'R11'), its calls (`EGON(...)` → args as written, quotes removed), bare
keywords (`WALIMON`) and R-parameter statements. `Nc.after[i]` is the position of every axis after
block i (None = never programmed, a str = set from a parameter); `Nc.moves` are the motion blocks
with mode, start, end and the modal feed and spindle speed.

The geometry helpers work in the DIN 66217 frame (reference §A7): `Machine.din(axis, value)` turns a
programmed coordinate into it. The `*_problems` functions return a list of one-line findings, empty
when the program agrees with the reference.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from hobbing_envelope import Solid, Sweep, intrusions, root_section_centre

AXES = "XYZABC"
NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)"
TOKEN = re.compile(r"""\s*(?:
      (?P<call>[A-Z_][A-Z0-9_]*)\((?P<args>[^()]*)\)
    | (?P<eqaddr>[A-Z])(?P<eqsub>\d*)=(?P<eqval>\S+)
    | (?P<addr>[A-Z])(?P<val>""" + NUMBER + r""")(?![A-Z0-9_=(])
    | (?P<word>[A-Z_][A-Z0-9_]*)
    )""", re.VERBOSE)
STATEMENT = re.compile(r"^(?:R\d+\s*=|IF\b|ENDIF\b|ELSE\b|GOTO[FB]?\b|WHILE\b|ENDWHILE\b|DEF\b|[A-Z_]\w*:)")
NON_MOTION_G = {4, 25, 26}      # axis words of these blocks are data (dwell, working-area limits)
HAND = {"R": 1, "L": -1}


class ReadError(ValueError):
    """The text is not a program this reader understands (which is a finding in itself)."""


@dataclass
class Block:
    index: int
    line_no: int
    text: str
    g: list[int] = field(default_factory=list)
    m: list[int] = field(default_factory=list)
    words: dict[str, float | str] = field(default_factory=dict)
    equals: set[str] = field(default_factory=set)          # addresses written with '=' (A=…)
    calls: dict[str, tuple[str, ...]] = field(default_factory=dict)
    keywords: set[str] = field(default_factory=set)
    statement: str | None = None

    @property
    def axes(self) -> dict[str, float | str]:
        return {a: v for a, v in self.words.items() if a in AXES}

    @property
    def is_motion(self) -> bool:
        return bool(self.axes) and not (set(self.g) & NON_MOTION_G) and self.statement is None


@dataclass
class Move:
    block: int
    mode: str                    # 'G0' or 'G1'
    start: dict
    end: dict
    feed: float | None
    speed: float | None          # spindle S in force

    def delta(self, axis: str) -> float:
        a, b = self.start.get(axis), self.end.get(axis)
        return (b - a) if isinstance(a, float) and isinstance(b, float) else 0.0


@dataclass
class Nc:
    lines: list[str]
    blocks: list[Block]
    after: list[dict]
    moves: list[Move]

    def where(self, token: str) -> list[int]:
        """Block indexes holding `token`: 'G94', 'M8', a call ('EGON'), a keyword ('WALIMON'),
        an address ('T', 'A'), or 'motion' / 'G0 move' / 'G1 move'."""
        moves = {m.block: m.mode for m in self.moves}
        return [b.index for b in self.blocks if _holds(b, token, moves.get(b.index))]

    def first(self, token: str) -> int | None:
        found = self.where(token)
        return found[0] if found else None

    def last(self, token: str) -> int | None:
        found = self.where(token)
        return found[-1] if found else None

    def calls(self, name: str) -> list[tuple[int, tuple[str, ...]]]:
        return [(b.index, b.calls[name]) for b in self.blocks if name in b.calls]


def _holds(block: Block, token: str, mode: str | None) -> bool:
    if token == "motion":
        return mode is not None
    if token.endswith(" move"):
        return mode == token.split()[0]
    code = re.fullmatch(r"([GM])(\d+)", token)
    if code:
        return int(code[2]) in (block.g if code[1] == "G" else block.m)
    return token in block.calls or token in block.keywords or token in block.words


def _code(line: str) -> str:
    out, quoted = [], False
    for ch in line:
        if ch == '"':
            quoted = not quoted
        if ch == ";" and not quoted:
            break
        out.append(ch)
    return "".join(out).strip()


def _value(text: str) -> float | str:
    return float(text) if re.fullmatch(NUMBER, text) else text


def read_block(index: int, line_no: int, code: str) -> Block:
    block = Block(index, line_no, code)
    body = re.sub(r"^N\d+\s*", "", code)
    if STATEMENT.match(body):
        block.statement = body
        return block
    pos = 0
    while pos < len(body):
        match = TOKEN.match(body, pos)
        if not match or match.end() == pos:
            raise ReadError(f"line {line_no}: cannot read {body[pos:]!r} in {code!r}")
        pos = match.end()
        _take(block, match)
    return block


def _take(block: Block, match: re.Match) -> None:
    if match["call"]:
        block.calls[match["call"]] = tuple(a.strip().strip('"') for a in match["args"].split(","))
    elif match["eqaddr"]:
        addr, value = match["eqaddr"], _value(match["eqval"])
        if addr == "M" and isinstance(value, float):
            block.m.append(int(value))      # M1=3: spindle 1 clockwise
        else:
            block.words[addr] = value        # S1=300, A=-1.7, Y=R11
            block.equals.add(addr)
    elif match["addr"]:
        addr, value = match["addr"], float(match["val"])
        if addr == "G":
            block.g.append(int(value))
        elif addr == "M":
            block.m.append(int(value))
        else:
            block.words[addr] = value
    else:
        block.keywords.add(match["word"])


def read(text: str) -> Nc:
    lines = text.splitlines()
    blocks = []
    for line_no, line in enumerate(lines):
        code = _code(line)
        if code and not code.startswith("%"):
            blocks.append(read_block(len(blocks), line_no, code))
    after, moves = _follow(blocks)
    return Nc(lines, blocks, after, moves)


def _follow(blocks: list[Block]) -> tuple[list[dict], list[Move]]:
    """Track every axis block by block (absolute G90 only; G91 is refused)."""
    position: dict = {a: None for a in AXES}
    mode, feed, speed = None, None, None
    after, moves = [], []
    for block in blocks:
        if 91 in block.g:
            raise ReadError(f"block {block.text!r}: incremental G91 is not read")
        for g in block.g:
            if g in (0, 1, 2, 3):
                mode = f"G{g}"
        if "S" in block.words:
            speed = block.words["S"]
        if "F" in block.words and 4 not in block.g:
            feed = block.words["F"]
        if block.is_motion:
            if mode not in ("G0", "G1"):
                raise ReadError(f"block {block.text!r}: motion in mode {mode}")
            start = dict(position)
            position.update(block.axes)
            moves.append(Move(block.index, mode, start, dict(position), feed if mode == "G1" else None, speed))
        after.append(dict(position))
    return after, moves


# ---------------------------------------------------------------- the records, as the test reads them

@dataclass(frozen=True)
class Machine:
    name: str = "hobber-840d"
    a: int = 1
    b: int = 1
    c: int = 1
    y: int = 1
    z: int = 1
    work_offset: str = "G54"
    table_speed_max: float = 120.0      # r/min of C
    rapid_rate: float = 8000.0          # mm/min, G0
    fixture: tuple = (25.0, 0.0)        # diameter, gap below the lowest unit's bottom face (0 Ø = none)
    tailstock: tuple = (25.0, 0.0)      # diameter, gap above the top face, when clamped (M20)
    load: tuple = (300.0, 100.0)        # programmed X, Z of the final position
    # The defaults describe the hand-written programs' machine; engine programs are checked against
    # the machine row the shop declared (tests/hobbing_reference_gears.read_machine).

    def din(self, axis: str, value):
        """A programmed coordinate in the DIN 66217 frame (§A7: program = DIN × sense)."""
        if not isinstance(value, float):
            return value
        return value * {"Y": self.y, "Z": self.z, "A": self.a}.get(axis, 1)


@dataclass(frozen=True)
class Hob:
    z0: int
    da0: float
    hand: str
    length: float
    tool_number: int = 1

    @property
    def r0(self) -> float:
        return self.da0 / 2


@dataclass(frozen=True)
class Unit:
    """One toothed unit in the DIN frame: faces at z_top and z_top − b."""
    z2: int
    b: float
    da: float
    df: float
    z_top: float = 0.0

    @property
    def bottom(self) -> float:
        return self.z_top - self.b


@dataclass(frozen=True)
class Gear:
    gear_class: str
    mn: float
    beta: float
    hand: str | None
    units: tuple[Unit, ...]
    cone: float = 0.0
    alpha: float = 20.0

    @property
    def first(self) -> Unit:
        return self.units[0]


# ---------------------------------------------------------------- the reference's numbers (DIN frame)

def lead_angle(mn: float, hob: Hob) -> float:
    """§B1: sin γ = z0·mn/d_m0, d_m0 = d_a0 − 2.5·mn; degrees."""
    return math.degrees(math.asin(hob.z0 * mn / (hob.da0 - 2.5 * mn)))


def swivel(gear: Gear, hob: Hob) -> float:
    """§A7: A = h_hob·γ − h_gear·β (worm wheels: 0, the shaft angle is 90°, §B10)."""
    if gear.gear_class == "worm_wheel":
        return 0.0
    h_gear = HAND.get(gear.hand or "R", 1)
    return HAND[hob.hand] * lead_angle(gear.mn, hob) - h_gear * gear.beta


def b_ratio(hob: Hob, z2: int, machine: Machine) -> tuple[int, int]:
    """§A7: k_B = −h_hob·z0/z2, programmed × c·b."""
    return -HAND[hob.hand] * hob.z0 * machine.c * machine.b, z2


def z_factor(gear: Gear, z2: int, machine: Machine) -> float:
    """§A7: k_Z = −h_gear·360·sinβ/(π·mn·z2) degrees of C per mm of Z, programmed × c·z."""
    size = 360 * math.sin(math.radians(gear.beta)) / (math.pi * gear.mn * z2)
    return -HAND[gear.hand] * size * machine.c * machine.z


def y_factor(gear: Gear, hob: Hob, machine: Machine) -> float:
    """§A7: k_Y = +360·cosγ/(π·mn·z2) for both hob hands, programmed × c·y."""
    gamma = math.radians(lead_angle(gear.mn, hob))
    return 360 * math.cos(gamma) / (math.pi * gear.mn * gear.first.z2) * machine.c * machine.y


def full_depth(unit: Unit, hob: Hob) -> float:
    """§B3: a = (d_f2 + d_a0)/2."""
    return (unit.df + hob.da0) / 2


def tip_radius_at(gear: Gear, unit: Unit, z: float) -> float:
    """The blank's tip radius at height z (DIN): the stated d_a holds at the top face Z = 0 and a
    taper changes it by tanδ per mm of Z (§B12)."""
    return unit.da / 2 + (z - unit.z_top) * math.tan(math.radians(gear.cone))


def approach_needed(h: float, hob: Hob, eta: float = 0.0, da2: float = 0.0) -> float:
    """§B7: spur √(h(d_a0 − h)); helical ≤ √(h(d_a0 − h))/cos η + tan η·√(h(d_a2 − h))."""
    if h <= 0:
        return 0.0
    spur = math.sqrt(h * (hob.da0 - h))
    eta = math.radians(abs(eta))
    return spur / math.cos(eta) + math.tan(eta) * math.sqrt(max(h * (da2 - h), 0.0))


ROUGHING_MAX = ((1.0, 2.0), (2.0, 3.0), (3.0, 3.5), (4.0, 4.0))   # §C: module → max f_a, mm/rev


def roughing_feed_max(module: float) -> float:
    """§C roughing maximum, linear between the table's modules, the end values outside."""
    points = ROUGHING_MAX
    if module <= points[0][0]:
        return points[0][1]
    for (m1, f1), (m2, f2) in zip(points, points[1:]):
        if module <= m2:
            return f1 + (f2 - f1) * (module - m1) / (m2 - m1)
    return points[-1][1]


def unit_solid(gear: Gear, unit: Unit) -> Solid:
    """The unit's tip body: d_a/2 at the top face, changing by tanδ per mm of Z (§B12)."""
    return Solid(unit.da / 2, unit.bottom, unit.z_top, math.tan(math.radians(gear.cone)), unit.z_top)


def root_solid(gear: Gear, unit: Unit) -> Solid:
    """The body under the unit's root (d_f/2 at the top face, the same cone): no cut may enter it."""
    return Solid(unit.df / 2, unit.bottom, unit.z_top, math.tan(math.radians(gear.cone)), unit.z_top)


def taper_depth(gear: Gear, unit: Unit, hob: Hob) -> float:
    """§B3 for a taper (§B12) at the top face: the hob's tip section in the plane Y = 0 is an ellipse
    r0 × r0/cos η; the last cut makes it touch the root line, so the centre lies its support distance
    off that line. (d_f2 + d_a0)/2 would cut the root r0·(1/cos δ − 1) too deep, measured along X."""
    return root_section_centre(unit.df / 2, hob.r0, gear.cone, swivel(gear, hob))


def layout_cuttable(gear: Gear, hob: Hob, tolerance: float = 0.002, shift: tuple = (0.0, 0.0)) -> bool:
    """Whether every unit can be cut at full depth from a clear approach (§B7) to a run-out beyond
    its other face, climb or conventional, without the hob (3-D, shifted within `shift`) entering
    another unit. When not, the correct answer is a refusal."""
    eta = swivel(gear, hob)
    for unit in gear.units:
        others = [unit_solid(gear, u) for u in gear.units if u != unit]
        x = full_depth(unit, hob)
        reach = approach_needed(tip_radius_at(gear, unit, unit.z_top) + hob.r0 - x, hob, eta, unit.da)
        paths = ((unit.z_top + reach, unit.bottom - 0.01), (unit.bottom - reach, unit.z_top + 0.01))
        sweeps = [Sweep(x, start, x, end, eta, shift, shift) for start, end in paths]
        if others and not any((intrusions([s] * len(others), others, hob.r0, hob.length) <= tolerance).all()
                              for s in sweeps):
            return False
    return True
