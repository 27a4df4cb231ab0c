"""A block of address words (`G1 X51.500 F36.0`, `G97 S800 M03`, `G18 G71 G90 G40 DIAMON`), read
word by word with the dialect's tables, and its shape checked: each address once, one G code of
each modal group, G25/G26 blocks with only their own words (a dwell G4 its time alone,
engine.verifier.dwell), an arc with its radius, a thread
with its pitch, and every move with its motion G code in the same block (the verifier reads each
block on its own, so it does not carry a modal G0/G1 over from earlier blocks). What the block
does to the machine state is kept as its events (engine.verifier.machine_state): its G
codes and keywords, which hold for its own motion, and its M codes and S, T, D words, which the
motion must not wait for (when an M code is output, before or after the motion, is the machine
builder's choice)."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, ClassVar, Literal

import msgspec

from .dwell import is_dwell, read_dwell
from .grammar import (
    ANGLE,
    AXES,
    BLOCK_SHAPES,
    CODE,
    DWELL,
    MOTION,
    OFFSET,
    POINT_REASON,
    SPEED,
    SPEED_LIMIT,
    TOOL,
    TOOL_AND_OFFSET,
    TOOL_OR_NAME,
    WORD_NEEDS_CODE,
    WORKING_AREA,
    Dialect,
)
from .machine_state import OFFSET_OFF, OFFSET_ON, TOOL_CHANGE
from .numbers import why_not_plain
from .refusals import Refused
from .words import READERS

if TYPE_CHECKING:
    from collections.abc import Callable

TOKEN = re.compile(r"([A-Z]+)(=?)(.*)")
EQUALS_KINDS = frozenset({"position", "angle", "feed", "speed", "radius", "pitch", "spindle position",
                          SPEED_LIMIT, TOOL_OR_NAME})


def _offset(number: float) -> str:
    return OFFSET_ON if number else OFFSET_OFF


# The events of a word, by its kind: an S gives the spindle a speed; a T changes the tool; D (840D)
# is the offset, D0 none; an ISO T<tool><offset> changes the tool and sets or cancels its offset.
WORD_EVENTS: dict[str, Callable[[float], tuple[str, ...]]] = {
    SPEED: lambda value: ("S",), TOOL: lambda value: (TOOL_CHANGE,), OFFSET: lambda number: (_offset(number),),
    SPEED_LIMIT: lambda value: ("LIMS",), TOOL_OR_NAME: lambda value: (TOOL_CHANGE,),
    TOOL_AND_OFFSET: lambda number: (TOOL_CHANGE, _offset(number % 100))}


class Block(msgspec.Struct, frozen=True):
    """An NC block as read: its address values, motion, positions and modal codes."""
    kind: ClassVar[Literal["block"]] = "block"
    values: dict[str, float]   # address -> value (G and M codes apart)
    motion: int | None         # the block's G0/G1/G2/G3/thread code
    area: str | None           # "lower" (G25) or "upper" (G26)
    positions: dict[str, float]   # X/Y/Z of the block
    moves: bool                # the block moves an axis (X, Y, Z or the swivel A)
    modal: frozenset[str]      # its G codes ("G90") and keywords: they hold for the block's own motion
    events: frozenset[str]     # its M codes ("M3") and word events (S, tool change, offset on/off)
    speed: float | None        # S
    feed: float | None         # F where it is a feed (not a G4 dwell's time)
    needs: str | None          # the motion whose needs the block must meet ("G1"), if it moves
    g_codes: frozenset[int] = frozenset()   # every G code of the block, whatever the state rules keep
    dwell: float | None = None   # seconds a dwell G4 holds the axes (engine.verifier.dwell)


def read_block(dialect: Dialect, code: str) -> Block:
    tokens = code.split()
    if is_dwell(tokens):
        return Block({}, None, None, {}, False, frozenset(), frozenset(), None, None, None, frozenset({DWELL}),
                     read_dwell(dialect, tokens))
    codes: dict[str, list[int]] = {"G": [], "M": []}
    values: dict[str, float] = {}
    keywords: set[str] = set()
    events: list[str] = []
    for token in tokens:
        _read_token(dialect, token, codes, values, keywords, events)
    groups = _groups(dialect, codes)
    _check_shape(dialect, codes, values, keywords)
    return _block(dialect, codes, groups, values, keywords, events)


def _block(dialect: Dialect, codes: dict[str, list[int]], groups: dict[int, str], values: dict[str, float],
           keywords: set[str], events: list[str]) -> Block:
    motion = area = None
    for code in codes["G"]:
        motion = code if groups[code] == MOTION else motion
        area = WORKING_AREA.get(code, area)
    positions = {axis: value for axis, value in values.items() if axis in AXES}
    moves = bool(positions) or any(dialect.addresses[address] == ANGLE for address in values)
    if moves and motion is None and area is None:
        raise Refused("a move without its G0/G1 (or G2/G3) in the same block: each block is verified on its own")
    effects = dialect.state.effects.keys()     # only events that change the state are kept
    modal = frozenset(effects & {*(f"G{code}" for code in codes["G"]), *keywords})
    kept = frozenset(effects & {*(f"M{code}" for code in codes["M"]), *events})
    feed = values.get("F")
    needs = f"G{motion}" if moves and area is None else None
    return Block(values, motion, area, positions, moves, modal, kept, values.get("S"), feed, needs,
                 frozenset(codes["G"]))


def _read_token(dialect: Dialect, token: str, codes: dict[str, list[int]], values: dict[str, float],
                keywords: set[str], events: list[str]) -> None:
    match = TOKEN.fullmatch(token)
    address, equals, text = match.groups() if match else ("", "", token)
    if address in dialect.keywords and not (equals or text):
        keywords.add(address)
        return
    kind = dialect.addresses.get(address)
    if kind is None:
        raise Refused(_unknown(dialect, token, address, text))
    if equals or len(address) > 1:
        _check_equals(dialect, address, kind, equals)
    value = READERS[kind](address + equals, text)
    if address in dialect.point_required and "." not in text:
        raise Refused(f"{address}{text} {POINT_REASON}; write {address}{text}.")
    if kind in WORD_EVENTS:
        events.extend(WORD_EVENTS[kind](value))
    if kind == CODE:
        codes[address].append(int(value))   # a G or M code is read as a whole number
    elif address in values:
        raise Refused(f"{address} twice in one block")
    else:
        values[address] = value


def _unknown(dialect: Dialect, token: str, address: str, text: str) -> str:
    if address and text.startswith("("):
        return f"{address}(…) is not a statement of the {dialect.name} grammar"
    return f"{token}: {why_not_plain(token, None) or f'not a word of the {dialect.name} grammar'}"


def _check_equals(dialect: Dialect, address: str, kind: str, equals: str) -> None:
    """840D: `X=12.5` is `X12.5`, and an address of two letters needs `=` (`CR=5`); ISO has no `=`."""
    if equals and not (dialect.equals_allowed and kind in EQUALS_KINDS):
        raise Refused(f"{address}= is not a form of the {dialect.name} grammar")
    if len(address) > 1 and not equals:
        raise Refused(f"{address} needs = before its value ({address}=…)")


def _groups(dialect: Dialect, codes: dict[str, list[int]]) -> dict[int, str]:
    groups = {}
    for letter in ("G", "M"):
        seen: dict[str, int] = {}
        for code in codes[letter]:
            group = dialect.code_group(letter, code)
            if group in seen:
                raise Refused(f"{letter}{seen[group]} and {letter}{code} in one block are both {group}")
            seen[group] = code
            if letter == "G":
                groups[code] = group
    return groups


def _check_shape(dialect: Dialect, codes: dict[str, list[int]], values: dict[str, float], keywords: set[str]) -> None:
    for code in codes["G"]:
        _check_alone(code, codes, values, keywords)
        needed = dialect.needs_words.get(code)
        if needed and needed not in values:
            raise Refused(f"G{code} without its {needed}")
    for address in values:
        if address in WORD_NEEDS_CODE and not WORD_NEEDS_CODE[address] & set(codes["G"]):
            wanted = "/".join(f"G{c}" for c in sorted(WORD_NEEDS_CODE[address]))
            raise Refused(f"{address} belongs to {wanted} in the same block")


def _check_alone(code: int, codes: dict[str, list[int]], values: dict[str, float], keywords: set[str]) -> None:
    """G25 and G26 stand in a block of their own with only their words, and give all of
    X, Y and Z, so no axis is left without a working-area limit."""
    if code not in BLOCK_SHAPES:
        return
    what, words = BLOCK_SHAPES[code]
    if len(codes["G"]) > 1 or codes["M"] or keywords or not set(values) <= words:
        raise Refused(f"a G{code} block ({what}) holds only {', '.join(sorted(words))}")
    if code in WORKING_AREA and set(values) != words:
        raise Refused(f"the {what} G{code} must give each of {', '.join(sorted(words))}")
    if not values:
        raise Refused(f"G{code} without its {'/'.join(sorted(words))}")
