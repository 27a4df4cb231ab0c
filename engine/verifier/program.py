"""The verifier: every emitted line of a program read with the grammar of the machine's dialect
(machine.kind and machine.dialect) and followed in order against the machine. It fails closed:
a line it cannot read as plain blocks of that dialect is refused like a line that exceeds a
limit, with the program, the line number, the block and the reason.

Followed in order: the headers where they must stand, naming the program itself (its own name,
a safe 840D name; an ISO number outside the macro range); each motion and statement only in
the machine state it needs (engine.verifier.machine_state: the working area, units,
modes, the spindle turning, the table coupled, a tool offset active); every X/Y/Z within the
travel and, on a hobber, within the working area G25/G26, whose limits lie within the travel
themselves; S at most the spindle's maximum and, with the coupling's ratio and differential
terms at the program's feeds, the table's; a thread's lead × S at most the feed bound; a lathe
arc whose radius reaches its ends, its extremes within the travel; the hob-shift clamp as
engine.verifier.shift_clamp says; M30 last (ISO: then the closing %)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ..machines.records import Machine
from ..names import NAME_RULES, is_safe
from .expansion import ExpansionRefused, PlainLine, expand
from .feed_mode import FeedMode
from .grammar import AXES, Dialect, dialect_for
from .limits import check_coupled_move, check_speed_limit, check_spindle, check_table, check_thread, check_travel
from .lines import HeaderLine, read_line, remembered_lines
from .machine_state import SWIVEL, Y_POSITION, State
from .refusals import LimitError, Refused, line_refused, shown_name
from .shift_clamp import ShiftClamp

if TYPE_CHECKING:
    from collections.abc import Callable

    from .blocks import Block
    from .lines import Line
    from .shift_clamp import ShiftLine
    from .statements import Statement

ARCS = (2, 3)
RAPID = 0
# An axis word's event, whose needs (where a dialect has them) hold before the block moves: Fanuc
# hobbing refuses a hob shift Y or swivel A while the table is synchronised (machine_state).
AXIS_EVENTS = {"Y": Y_POSITION, "A": SWIVEL}


def verify_program(lines: list[str], machine: Machine, program_name: str | None) -> None:
    """Raises LimitError for the first line refused; returns only for a program read whole, whose
    header names `program_name` (the job's program_name)."""
    try:
        dialect = dialect_for(machine)
    except Refused as refusal:
        raise LimitError(f"machine {machine.name}: {refusal}; nothing stored") from None
    try:
        plain = expand(dialect.expander, lines, machine)
    except ExpansionRefused as refusal:
        raise line_refused(program_name or "the program", refusal.number, refusal.source, str(refusal)) from None
    except Refused as refusal:
        raise LimitError(f"{shown_name(program_name or 'the program')}: {refusal}; nothing stored") from None
    if plain is None:
        _read_as_written(lines, dialect, machine, program_name)
    else:
        _read_expanded(plain, dialect, machine, program_name)


def _read_as_written(lines: list[str], dialect: Dialect, machine: Machine, program_name: str | None) -> None:
    """The engine's own dialects: every line is a plain line, read as it is (remembered per text)."""
    walk = ProgramReading(dialect, machine, len(lines), program_name)
    remembered, number = remembered_lines(dialect), 0
    try:
        for number, line in enumerate(lines, start=1):
            found = remembered.get(line) if type(line) is str else None
            walk.take(number, read_line(dialect, line) if found is None or isinstance(found, Refused) else found)
        walk.finish()
    except Refused as refusal:
        raise line_refused(program_name or "the program", number, lines[number - 1] if number else "",
                           str(refusal)) from None


def _read_expanded(plain: list[PlainLine], dialect: Dialect, machine: Machine, program_name: str | None) -> None:
    """A dialect with an expander: its plain lines read in order (places counted in them), and a
    refusal names the line of the program as written that the refused plain line comes from."""
    walk = ProgramReading(dialect, machine, len(plain), program_name)
    index = 0
    try:
        for index, line in enumerate(plain, start=1):
            walk.take(index, read_line(dialect, line.text))
        walk.finish()
    except Refused as refusal:
        where = plain[index - 1] if index else (plain[-1] if plain else PlainLine("", 0, ""))
        raise line_refused(program_name or "the program", where.number, where.source, str(refusal)) from None


class ProgramReading:
    """What the lines so far have set: the machine state (engine.verifier.machine_state),
    the working area and the bounds it leaves each axis, the position, the spindle speed, the
    feed, the table's coupling ratio and differential factors, the hob-shift clamp."""

    def __init__(self, dialect: Dialect, machine: Machine, count: int, program_name: str | None) -> None:
        self.dialect, self.machine, self.count, self.program_name = dialect, machine, count, program_name
        self.state = State(dialect.state)
        self.required = {place: header for header in dialect.headers for place in header.required}
        self.area: dict[str, dict[str, float]] = {"lower": {}, "upper": {}}
        self.travel: dict[str, tuple[float, float]] = {
            axis: (getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max")) for axis in AXES}
        self.bounds = self.travel                     # travel, narrowed by the working area once set
        self.position: dict[str, float] = {}
        self.speed: float | None = None
        self.feed: float | None = None
        self.ratio: float | None = None
        self.coupled_axes: tuple[str, ...] | None = None
        self.differential: dict[str, float] = {}
        self.clamp = ShiftClamp()
        self.numbered = False
        self.feed_mode = FeedMode(machine)

    def take(self, number: int, line: Line) -> None:
        framed = isinstance(line, HeaderLine) and "last" in line.places
        if number == 1 and self.dialect.framing_optional and not framed:
            self._unframed()
        if number <= 2 or number == self.count or self.state.ended:
            self._check_place(number, line)
        if self.clamp.at and line.kind != "shift":
            self.clamp.interrupted()
        TAKERS[line.kind](self, number, line)

    def finish(self) -> None:
        self.clamp.interrupted()
        if not self.state.ended:
            raise Refused("the program does not end with M30")

    def _unframed(self) -> None:
        """ISO without the tape marks (a program as stored in the control): the program number
        line comes first, and no % is required at the end."""
        number_line = self.required.get("second")
        self.required = {"first": number_line} if number_line is not None else {}

    def _check_place(self, number: int, line: Line) -> None:
        """The header a place requires stands there; after M30 nothing but the closing header."""
        places = [place for place, here in (("first", number == 1), ("second", number == 2),
                                            ("last", number == self.count)) if here]
        closing = line.kind == "header" and "last" in places and "last" in line.places
        if self.state.ended and not closing:
            raise Refused("a line after M30: the program ends there, and the control reads nothing after it")
        for place in places:
            header = self.required.get(place)
            if header is not None and (line.kind != "header" or line.what != header.what):
                raise Refused(f"the {place} line must be the {header.what}")

    def _header(self, number: int, line: HeaderLine) -> None:
        places = {"first": number == 1, "second": number == 2, "last": number == self.count}
        if not any(places[place] for place in line.places):
            raise Refused(f"the {line.what} belongs only in the {' or '.join(sorted(line.places))} line")
        if line.name is not None:
            self._check_name(line.name)
        if line.number is not None:
            self._check_number(line.number)

    def _check_number(self, number: int) -> None:
        numbers, reserved = self.dialect.program_numbers, self.dialect.reserved_numbers
        if self.numbered:
            raise Refused(f"a second program number O{number:04d}: one program has one number")
        self.numbered = True
        if numbers is not None and (number not in numbers or (reserved is not None and number in reserved)):
            ranges = f"O{numbers[0]:04d} … O{numbers[-1]:04d}"
            if reserved is not None:
                ranges = f"O{numbers[0]:04d} … O{reserved[0] - 1:04d} and O{reserved[-1] + 1:04d} … O{numbers[-1]:04d}"
            raise Refused(f"program number O{number:04d} is outside {ranges} "
                          "(O9000 … O9999 hold the machine builder's macros)")

    def _check_name(self, name: str) -> None:
        """The control stores the program under the header's name: it must be this program's
        (another name would replace that program on a read-in) and a safe 840D name."""
        if self.program_name is None:
            raise Refused(f"the header names program {shown_name(name)}, but the job names none (params.program_name)")
        if name != self.program_name:
            raise Refused(f"the header names program {shown_name(name)}, but this program is "
                          f"{shown_name(self.program_name)}: a read-in would store it as the other; "
                          f"give program_name {shown_name(name)} in the job's params")
        if not is_safe("program", name):
            raise Refused(f"the program name {shown_name(name)} is not {NAME_RULES['program'].rule}")

    def _comment(self, number: int, line: Line) -> None:
        return None

    def _block(self, number: int, block: Block) -> None:
        if block.modal:
            self.state.apply(block.modal)
        if block.feed is not None:
            self.feed = block.feed
        self.feed_mode.take(block)
        # the move runs at the S of its own block; the speed itself is set (and checked) below
        self.feed_mode.check(block, self.feed, self.speed if block.speed is None else block.speed)
        if block.area:
            self._set_area(block)
        elif block.moves:
            self._move(block)
        if block.events:
            for event in block.events:
                self.state.check_event(event, block.events - {event})
            self.state.apply(block.events)
        if block.speed is not None:
            self._set_speed(block.speed)
        if "LIMS" in block.values:
            check_speed_limit(block.values["LIMS"], self.machine)

    def _move(self, block: Block) -> None:
        assert block.needs is not None   # a block that moves, outside G25/G26, names its motion
        for axis, event in AXIS_EVENTS.items():
            if axis in block.values:
                self.state.check_event(event, block.events)
        self.state.check(block.needs, block.events)
        self._check_motion(block.positions)
        if block.motion in ARCS:
            self._check_arc(block)
        if block.motion in self.dialect.thread_lead:
            address = self.dialect.thread_lead[block.motion]
            assert self.speed is not None   # the thread's needs (engine.verifier.machine_state) hold an S
            check_thread(block.values[address], self.speed, address)
        if self.differential and self.ratio is not None:
            self._check_differential(block.motion, block.positions, self.ratio)
        self.position.update(block.positions)
        if "Y" in block.positions:
            self.state.apply(frozenset({Y_POSITION}))

    def _set_area(self, block: Block) -> None:
        for axis, value in block.positions.items():
            low, high = self.travel[axis]
            if not low <= value <= high:
                check_travel(axis, value, self.machine, "working-area limit ")
        if block.positions:
            area_once_problem(str(block.area), bool(self.area[str(block.area)]), bool(self.position))
        self.area[str(block.area)] = dict(block.positions)
        lower, upper = self.area["lower"], self.area["upper"]
        self.bounds = {axis: (max(low, lower.get(axis, -math.inf)), min(high, upper.get(axis, math.inf)))
                       for axis, (low, high) in self.travel.items()}

    def _check_motion(self, positions: dict[str, float]) -> None:
        bounds = self.bounds
        for axis, value in positions.items():
            low, high = bounds[axis]
            if not low <= value <= high:
                self._refuse_position(axis, value)

    def _refuse_position(self, axis: str, value: float) -> None:
        check_travel(axis, value, self.machine)
        low, high = self.area["lower"].get(axis), self.area["upper"].get(axis)
        raise Refused(f"{axis}{value:g} lies outside the working area G25/G26 {axis} {low:g}…{high:g}")

    def _check_arc(self, block: Block) -> None:
        from .arcs import arc_box, check_radius  # a lathe's arcs: a hobbing program has none (issue 28: start-up)

        if not {"X", "Z"} <= self.position.keys():
            raise Refused("an arc from an unknown start point: program X and Z before it")
        end = {**self.position, **block.positions}
        assert self.dialect.arc_radius is not None   # a dialect with arcs names their radius word
        radius = block.values[self.dialect.arc_radius]
        check_radius(self.position["X"], self.position["Z"], end["X"], end["Z"], radius)
        box = arc_box(self.position["X"], self.position["Z"], end["X"], end["Z"], radius, block.motion == 3)
        for axis, extremes in box.items():
            for extreme in extremes:
                check_travel(axis, extreme, self.machine, "the arc reaches ")

    def _check_differential(self, motion: int | None, positions: dict[str, float], ratio: float) -> None:
        """A leading axis moving while coupled turns the table by its factor: at the block's
        feed, or for G0 at the machine's rapid rate (engine.verifier.limits)."""
        check_coupled_move(motion == RAPID, self.feed, positions, (self.speed, ratio, self.differential),
                           self.machine, self.position)

    def _set_speed(self, speed: float) -> None:
        check_spindle(speed, self.machine)
        self.speed = speed
        self._check_table()

    def _check_table(self) -> None:
        if self.speed is not None and self.ratio is not None:
            check_table(self.speed, self.ratio, self.machine)

    def _statement(self, number: int, statement: Statement) -> None:
        self.state.check(statement.name)
        STATEMENT_TAKERS[statement.name](self, statement)
        self.state.apply(frozenset({statement.name}))

    def _define_coupling(self, statement: Statement) -> None:
        self.coupled_axes = statement.leading

    def _couple(self, statement: Statement) -> None:
        if statement.leading != self.coupled_axes:
            raise Refused(f"EGON couples {','.join(statement.leading)} but EGDEF defined "
                          f"{','.join(self.coupled_axes or ()) or 'nothing'}")
        self.ratio, self.differential = statement.ratio, dict(statement.factors)
        self._check_table()

    def _uncouple(self, statement: Statement) -> None:
        self.ratio, self.differential = None, {}

    def _synchronise(self, statement: Statement) -> None:
        """Fanuc G81 (engine.verifier.synchronisation): the table at |L|/T of the hob plus the
        helical compensation's degrees of C per mm of Z that Q and P give (fanuc-egb.md §F4),
        bounded at each Z move; a second G81 while on replaces both. One without Q and P while a
        compensation is on is refused: whether the control keeps that is not in the manual (§F2)."""
        if self.differential and not statement.factors:
            raise Refused(f"{statement.name} without Q and P after a {statement.name} that gave them, the table "
                          f"still synchronised: whether the control keeps their compensation is not in the manual "
                          "(fanuc-egb.md §F2); write Q and P again (P0. for a spur gear)")
        self.ratio, self.differential = statement.ratio, dict(statement.factors)
        self._check_table()

    def _delete_coupling(self, statement: Statement) -> None:
        self.coupled_axes = self.ratio = None
        self.differential = {}

    def _shift(self, number: int, line: ShiftLine) -> None:
        ends = self.clamp.take(line)
        if ends is not None:
            self.state.check(f"G{RAPID}")
            for value in ends:
                self._check_motion({"Y": value})
            if self.differential and self.ratio is not None:
                self._check_differential(RAPID, {"Y": ends[0]}, self.ratio)
            self.state.apply(frozenset({Y_POSITION}))


# each taker takes the kind of line it is named by
TAKERS: dict[str, Callable[[ProgramReading, int, Any], None]] = {
    "header": ProgramReading._header, "comment": ProgramReading._comment, "block": ProgramReading._block,
    "statement": ProgramReading._statement, "shift": ProgramReading._shift}
STATEMENT_TAKERS: dict[str, Callable[[ProgramReading, Statement], None]] = {
    "EGDEF": ProgramReading._define_coupling, "EGON": ProgramReading._couple,
    "EGOFS": ProgramReading._uncouple, "EGDEL": ProgramReading._delete_coupling,
    "G81": ProgramReading._synchronise, "G81.4": ProgramReading._synchronise,
    "G80": ProgramReading._uncouple, "G80.4": ProgramReading._uncouple}


def area_once_problem(limit: str, already_set: bool, moved: bool) -> None:
    """The working area (G25/G26 X… Y… Z…, reference §A4) is set once, before the first move: a
    second G25/G26, or one after a move, would widen the area the rest of the program is held to
    after the start was checked against it. (G25/G26 S… limit the spindle speed and are not this.)"""
    word = "G25" if limit == "lower" else "G26"
    if already_set:
        raise Refused(f"{word} again: the working area is set once, before the first move (reference §A4); "
                      "a second limit would widen it after the checked start")
    if moved:
        raise Refused(f"{word} after the first move: the working area is set once, before any motion "
                      "(reference §A4)")
