"""Numbers that name something (issue 17): a block, a subprogram, a program, a tool edge, an
offset register, a spindle, a channel. They are references, not quantities: a parameter whose
value happens to equal one (a depth of 100, one pass) must not turn `G71.1 Q100` (the contour
subprogram O100) or the 840D tool edge `D1` into that parameter, or the class made with another
value calls a contour or an edge the program does not have.

Which numbers are references is decided from the block the number is in, as data: REFERENCES
names an address, the G/M codes of the blocks where that address names something (none: every
block) and the codes or addresses under which it is a quantity after all (LinuxCNC's G70 `P2`
counts passes, the `D` of G71 is a depth, that of G41.1/G42.1 a diameter). STATEMENTS names the
Sinumerik statements whose arguments are numbers of spindles, channels, marks or edges
(`SETMS(1)`), and a number written right before `=` is the extension of its address (`S1=200`:
spindle 1). The plain form of a parameter never binds a reference. A bound form naming the
address binds it, unless the number is a block or program number (`target`): jumping to another
block or calling another program is never a job's parameter, so that is refused.

Some numbers are quantities of another kind than the word's usual one (issue 27), in data too:
the `S` of `G50 S1000`/`G92 S1000` is the spindle speed limit in r/min (a clamp), not the G96
surface speed in m/min; the 840D `LIMS=` is that limit too; the `U` `W` `R` of the lathe cycles
G71–G76 are the depth of cut, the finishing allowances and the retract (lengths), not the feed
that the same block's `F` gives. A `never` rule is bound by no parameter (the clamp; a number
inside `[…]`, which is an array subscript such as `TECH_TIME[4]` or a constant of a LinuxCNC
expression `[#1+2]`: binding the 4 makes the program read another variable)."""
from __future__ import annotations

import msgspec

from ..nc.tokens import NAME, SPACE, SYMBOL, WORD, LineFacts


class Reference(msgspec.Struct, frozen=True):
    """In a block with one of `within` (empty: any block) and none of `unless`, the number after
    `address` names `names`; `target`: a block or program number (never a parameter)."""
    address: str
    names: str
    within: frozenset = frozenset()
    unless: frozenset = frozenset()
    target: bool = False
    never: bool = False   # no parameter binds it, not even one naming the address


def _codes(*codes: str) -> frozenset:
    return frozenset(codes)


_CONTOUR_CYCLES = _codes("G70", "G71", "G71.1", "G71.2", "G72", "G72.1", "G72.2")
_REPEATED = _codes("M98", "M198", "G65", "G73", "G81", "G82", "G83", "G84", "G85", "G86", "G87", "G88", "G89")
_DEPTH_OR_DIAMETER = _CONTOUR_CYCLES | _codes("G73", "G41.1", "G42.1")
_LATHE_CYCLES = _CONTOUR_CYCLES | _codes("G73", "G74", "G75", "G76")
_CLAMP = "the spindle speed limit in r/min (a clamp, not a spindle speed)"

# First row that applies wins. Fanuc's G73 is a contour cycle on lathes and peck drilling (with Z)
# on mills; LinuxCNC's G70 has D and E, and its P counts passes where Fanuc's names a block. A
# block cannot tell whether G96's D is the 840D tool edge or LinuxCNC's speed limit: it is
# taken for the edge (fail closed), and the user who means the limit names D.
REFERENCES = (
    Reference("P", "the first block of the contour", _codes("G70", "G71", "G72", "G73"), _codes("D", "E", "Z"), True),
    Reference("Q", "the contour (its last block, or its subprogram)", _CONTOUR_CYCLES, target=True),
    Reference("Q", "the last block of the contour", _codes("G73"), _codes("Z"), True),
    Reference("P", "the subprogram called", _codes("M98", "M198", "G65"), target=True),
    Reference("P", "the block returned to", _codes("M99"), target=True),
    Reference("L", "the subprogram called", _codes("G25", "G27"), target=True),
    Reference("P", "the coordinate system or tool whose offsets are set", _codes("G10", "G54.1")),
    Reference("P", "an input, output or switch", _codes("M50", "M51", "M52", "M53", "M62", "M63", "M64", "M65", "M66")),
    Reference("E", "an analog channel", _codes("M66", "M67", "M68")),
    Reference("L", "a subprogram, an offset kind or a tool orientation", unless=_REPEATED),
    Reference("D", "the tool edge (Sinumerik) or, in LinuxCNC, G96's speed limit; a bound form naming D binds it",
              _codes("G96")),
    Reference("D", "the tool edge or offset register", unless=_DEPTH_OR_DIAMETER),
    Reference("H", "the tool length offset register", unless=_codes("G76")),
    Reference("S", _CLAMP, _codes("G50", "G92"), never=True),
    Reference("LIMS", _CLAMP + "; a bound form naming LIMS binds it"),
    Reference("U", "the cycle's depth of cut or X finishing allowance (a length, not a feed)", _LATHE_CYCLES),
    Reference("W", "the cycle's Z finishing allowance or depth (a length, not a feed)", _LATHE_CYCLES),
    Reference("R", "the cycle's retract or taper (a length, not a feed)", _LATHE_CYCLES),
)
IN_BRACKETS = Reference("", "a subscript or the constant of an expression inside […]", never=True)

# Sinumerik statements whose numeric arguments name something.
STATEMENTS = {
    "SETMS": "the master spindle", "SPCON": "a spindle", "SPCOF": "a spindle", "GETD": "a tool edge",
    "SETM": "a wait mark", "CLEARM": "a wait mark", "WAITM": "a wait mark and its channels",
    "WAITE": "a channel", "START": "a channel", "INIT": "a channel", "CHANDATA": "a channel",
}
EXTENSION = Reference("", "the spindle, axis or channel its address is for")

# The code addresses (nc_params.CODE_ADDRESSES) that name something, for the warning.
CODE_NAMES = {"N": "a block", "O": "a program", "T": "a tool"}


def block_context(facts: LineFacts) -> frozenset:
    """What a block says, for REFERENCES: its G/M codes (`G71.1`) and its words (`D`, `SETMS`)."""
    return facts.codes | facts.words


def reference_at(tokens, index: int, context: frozenset) -> Reference | None:
    """The reference the number tokens[index] is, or None for a quantity."""
    if _in_brackets(tokens, index):
        return IN_BRACKETS
    if _extends_address(tokens, index):
        return EXTENSION
    statement = _statement_of(tokens, index)
    if statement in STATEMENTS:
        return Reference("", STATEMENTS[statement])
    address = tokens[index].address
    return next((rule for rule in REFERENCES if rule.address == address and _applies(rule, context)), None)


def _applies(rule: Reference, context: frozenset) -> bool:
    return (not rule.within or bool(rule.within & context)) and not (rule.unless & context)


def _extends_address(tokens, index: int) -> bool:
    """`S1=200`: the number written on its address and followed by `=` (M1=3's 1 is an M code)."""
    following = tokens[index + 1] if index + 1 < len(tokens) else None
    before = tokens[index - 1] if index else None
    return (following is not None and following.kind == SYMBOL and following.text == "="
            and before is not None and before.kind == WORD)


def _in_brackets(tokens, index: int) -> bool:
    """Whether tokens[index] is inside `[…]` (more `[` than `]` before it on the line)."""
    depth = 0
    for token in tokens[:index]:
        if token.kind == SYMBOL:
            depth += {"[": 1, "]": -1}.get(token.text, 0)
    return depth > 0


def _statement_of(tokens, index: int) -> str | None:
    """The statement whose parentheses hold tokens[index] (`SETMS(1)` → SETMS), upper case."""
    depth = 0
    for position in range(index - 1, -1, -1):
        text = tokens[position].text
        depth += {")": 1, "(": -1}.get(text, 0) if tokens[position].kind == SYMBOL else 0
        if depth < 0:
            return _name_before(tokens, position)
    return None


def _name_before(tokens, position: int) -> str | None:
    for token in reversed(tokens[:position]):
        if token.kind != SPACE:
            return token.text.upper() if token.kind in (WORD, NAME) else None
    return None
