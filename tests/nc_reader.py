"""A small reader of Siemens 840D main programs, for tests only.

Written independently of `engine.verifier` on purpose: the tests must not share code with
the engine they check. It understands the subset the hobbing templates write:

* blocks with an optional `N…` number and a `;` comment;
* G codes (G0/G1 are the modal motion group; G25/G26 with axis words set working-area
  limits and are no motion);
* axis words X/Y/Z/A/B/C as `X12.5` or `A=-1.763`, S, F (modal), the tool call T and its edge D,
  the spindle orientation `SPOS=0`, M codes (`M3`, also `M1=3`);
* calls `NAME(arg, …)` such as `EGDEF(C,B,1,Z,1)`, `EGON(C,"FINE",B,-1,19)`, `EGOFS(C)`,
  whose arguments are kept as written (quotes removed from strings);
* bare keywords (`WALIMON`, `WALIMOF`, …);
* R-parameter statements (`R11=R11+2.5`, `IF (R11<-20) OR (R11>20)`, `ENDIF`) as blocks
  without motion, kept in `Block.statement`; an axis set from a parameter (`G0 Y=R11`)
  has no known value (`Block.params` holds its name).

`read_program(text)` returns a `Program`: its blocks, the moves (mode, start, end, feed,
block index) with the modal position tracked from block to block, and an index of events
(`"G94"`, `"M8"`, `"EGON"`, `"A"`, `"WALIMON"`, …) to the blocks they occur in.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

AXES = ("X", "Y", "Z", "A", "B", "C")
MOTION = {0: "G0", 1: "G1", 2: "G2", 3: "G3"}
# G codes after which the axis words of the block are data, not a motion target.
NON_MOTION_G = {4, 25, 26, 74, 75, 110, 111, 112, 500, 53, 153}

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)"
_TOKEN = re.compile(
    r"""\s*(?:
        (?P<call>[A-Z_][A-Z0-9_]*)\s*\((?P<args>[^()]*)\)       # NAME(args)
      | (?P<eq>[A-Z][A-Z0-9_]*)\s*=\s*(?P<eqval>""" + _NUMBER + r""")  # A=-1.5, M1=3, S1=300
      | (?P<eqparam>[XYZ])\s*=\s*(?P<param>R\d+)                     # Y=R11: position from an R parameter
      | (?P<addr>[A-Z])(?P<val>""" + _NUMBER + r""")           # X12.5, G0, M30
      | (?P<word>[A-Z_][A-Z0-9_]*)                              # WALIMON
    )""",
    re.VERBOSE,
)


_STATEMENT = re.compile(r"^(R\d+\s*=|IF\b|ENDIF\b|ELSE\b)")


class ReadError(ValueError):
    pass


@dataclass(frozen=True)
class Call:
    name: str
    args: tuple[str, ...]

    def __str__(self) -> str:
        return f"{self.name}({','.join(self.args)})"


@dataclass
class Block:
    index: int                     # position among the blocks (comment-only lines are no blocks)
    line_no: int                   # 0-based line of the program text
    text: str
    number: int | None = None      # N…
    g: list[int] = field(default_factory=list)
    words: dict[str, float] = field(default_factory=dict)   # axis words and S/F
    raw: dict[str, str] = field(default_factory=dict)       # the same words as written
    m: list[int] = field(default_factory=list)
    calls: list[Call] = field(default_factory=list)
    keywords: list[str] = field(default_factory=list)
    comment: str | None = None
    statement: str | None = None   # R11=R11+2.5, IF …, ENDIF
    params: dict[str, str] = field(default_factory=dict)   # axis → R parameter (Y=R11)

    @property
    def axes(self) -> dict[str, float]:
        return {k: v for k, v in self.words.items() if k in AXES}

    def call(self, name: str) -> Call | None:
        return next((c for c in self.calls if c.name == name), None)


@dataclass(frozen=True)
class Move:
    block: int                     # index of the block that programs it
    mode: str                      # "G0", "G1", …
    start: dict[str, float | None]
    end: dict[str, float | None]
    feed: float | None             # modal F in effect (None for rapid or never set)

    @property
    def changed(self) -> set[str]:
        """Axes programmed in the block whose value differs from the start."""
        return {a for a in AXES if self.end[a] is not None and self.end[a] != self.start[a]}


@dataclass
class Program:
    lines: list[str]
    comments: list[tuple[int, str]]            # (line_no, text after ';') of comment-only lines
    blocks: list[Block]
    moves: list[Move]
    events: dict[str, list[int]]               # event → block indexes, in order

    def index(self, event: str) -> int | None:
        """Block index of the first occurrence of `event`, or None."""
        found = self.events.get(event)
        return found[0] if found else None

    def indexes(self, event: str) -> list[int]:
        return list(self.events.get(event, []))

    def block_with(self, event: str) -> Block | None:
        i = self.index(event)
        return None if i is None else self.blocks[i]

    def moves_in(self, mode: str) -> list[Move]:
        return [m for m in self.moves if m.mode == mode]


def _split_comment(line: str) -> tuple[str, str | None]:
    in_string = False
    for i, ch in enumerate(line):
        if ch == '"':
            in_string = not in_string
        elif ch == ";" and not in_string:
            return line[:i], line[i + 1:]
    return line, None


def _split_args(args: str) -> tuple[str, ...]:
    if not args.strip():
        return ()
    out = []
    for arg in args.split(","):
        arg = arg.strip()
        if len(arg) >= 2 and arg[0] == arg[-1] == '"':
            arg = arg[1:-1]
        out.append(arg)
    return tuple(out)


def _parse_block(index: int, line_no: int, line: str) -> Block | None:
    code, comment = _split_comment(line)
    code_up = code.strip().upper()
    if not code_up:
        return None
    block = Block(index=index, line_no=line_no, text=line, comment=comment)
    if _STATEMENT.match(code_up):
        block.statement = code.strip()
        return block
    pos = 0
    while pos < len(code_up):
        if code_up[pos].isspace():
            pos += 1
            continue
        match = _TOKEN.match(code_up, pos)
        if not match or match.end() == pos:
            raise ReadError(f"line {line_no + 1}: cannot read {code[pos:]!r} in {line!r}")
        pos = match.end()
        if match["eqparam"]:
            block.params[match["eqparam"]] = match["param"]
        elif match["call"]:
            # the original case of the arguments is kept (strings like "FINE")
            start, end = match.span("args")
            block.calls.append(Call(match["call"], _split_args(code[start:end])))
        elif match["eq"]:
            name, value = match["eq"], match["eqval"]
            if name in AXES or name in ("S", "F", "SPOS"):
                block.words[name] = float(value)
                block.raw[name] = value
            elif re.fullmatch(r"M\d+", name):      # M1=3: M code 3 for spindle 1
                block.m.append(int(float(value)))
            elif re.fullmatch(r"S\d+", name):
                block.words["S"] = float(value)
                block.raw["S"] = value
            else:
                raise ReadError(f"line {line_no + 1}: unknown assignment {name}= in {line!r}")
        elif match["addr"]:
            address, value = match["addr"], match["val"]
            if address == "G":
                block.g.append(int(float(value)))
            elif address == "M":
                block.m.append(int(float(value)))
            elif address == "N":
                block.number = int(float(value))
            elif address in AXES or address in ("S", "F", "T", "D"):
                block.words[address] = float(value)
                block.raw[address] = value
            else:
                raise ReadError(f"line {line_no + 1}: unknown address {address} in {line!r}")
        else:
            block.keywords.append(match["word"])
    return block


def read_program(text: str) -> Program:
    lines = text.splitlines()
    blocks: list[Block] = []
    comments: list[tuple[int, str]] = []
    for line_no, line in enumerate(lines):
        stripped = line.strip()
        if stripped.startswith("%"):          # %_N_NAME_MPF file header
            continue
        block = _parse_block(len(blocks), line_no, line)
        if block is None:
            if stripped.startswith(";"):
                comments.append((line_no, stripped[1:]))
            continue
        blocks.append(block)

    position: dict[str, float | None] = {a: None for a in AXES}
    mode: str | None = None
    feed: float | None = None
    moves: list[Move] = []
    events: dict[str, list[int]] = {}

    def event(name: str, i: int) -> None:
        events.setdefault(name, []).append(i)

    for block in blocks:
        i = block.index
        for g in block.g:
            event(f"G{g}", i)
        for m in block.m:
            event(f"M{m}", i)
        for c in block.calls:
            event(c.name, i)
        for k in block.keywords:
            event(k, i)
        for w in block.words:
            event(w, i)
        for axis in block.params:          # G0 Y=R11: the position is known only at run time
            position[axis] = None
            event(f"{axis}=R", i)
        if block.statement:
            event(block.statement.split("=")[0].split()[0].upper(), i)

        motion = [g for g in block.g if g in MOTION]
        if motion:
            mode = MOTION[motion[-1]]
        if "F" in block.words:
            feed = block.words["F"]
        axes = block.axes
        if not axes or any(g in NON_MOTION_G for g in block.g):
            continue
        if mode is None:
            raise ReadError(f"line {block.line_no + 1}: axis motion before any G0/G1: {block.text!r}")
        start = dict(position)
        position.update(axes)
        moves.append(Move(i, mode, start, dict(position), None if mode == "G0" else feed))
        event("motion", i)
        event(f"move {mode}", i)
    return Program(lines, comments, blocks, moves, events)
