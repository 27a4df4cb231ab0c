"""The verifier: every emitted line of a program read with the grammar of the machine's dialect
(machine.kind and machine.dialect) and followed in order against the machine. It fails closed:
a line it cannot read as plain blocks of that dialect is refused like a line that exceeds a
limit, with the program, the line number, the block and the reason.

Followed in order: headers only where they belong; motion only after what the dialect needs
first (G25, G26 and WALIMON on a hobber, DIAMON on an 840D lathe); every X/Y/Z within the
travel and, on a hobber, within the working area G25/G26, whose limits lie within the travel
themselves; S at most the spindle's maximum and, with the EGON ratio, the table's; a lathe arc's
extremes within the travel; the hob-shift clamp as engine.programs.verifier.shift_clamp says."""
from __future__ import annotations

import math

from ...gears.records import Machine
from .arcs import arc_box
from .grammar import AXES, Dialect, dialect_of
from .limits import check_spindle, check_table, check_travel
from .lines import read_line, remembered_lines
from .refusals import LimitError, Refused, line_refused
from .shift_clamp import ShiftClamp

ARCS = (2, 3)


def verify_program(lines: list[str], machine: Machine, program_name: str = "program") -> None:
    """Raises LimitError for the first line refused; returns only for a program read whole."""
    try:
        dialect = dialect_of(machine.kind, machine.dialect)
    except Refused as refusal:
        raise LimitError(f"machine {machine.name}: {refusal}; nothing stored") from None
    walk = Walk(dialect, machine, len(lines))
    remembered, number = remembered_lines(dialect), 0
    try:
        for number, line in enumerate(lines, start=1):
            found = remembered.get(line) if type(line) is str else None
            walk.take(number, read_line(dialect, line) if found is None or found.__class__ is Refused else found)
        walk.finish()
    except Refused as refusal:
        raise line_refused(program_name, number, lines[number - 1] if number else "", str(refusal)) from None


class Walk:
    """What the lines so far have set: facts (G25, G26, WALIMON, DIAMON), the working area and
    the bounds it leaves each axis, the lathe's position, the spindle speed and the table's
    coupling ratio, the hob-shift clamp."""

    def __init__(self, dialect: Dialect, machine: Machine, count: int):
        self.dialect, self.machine, self.count = dialect, machine, count
        self.facts: set = set()
        self.ready = not dialect.motion_needs        # what motion needs has been set
        self.area = {"lower": {}, "upper": {}}
        self.travel = {axis: (getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max"))
                       for axis in AXES}
        self.bounds = self.travel                     # travel, narrowed by the working area once set
        self.position: dict = {}
        self.speed = self.ratio = self.coupled_axes = None
        self.clamp = ShiftClamp()

    def take(self, number: int, line) -> None:
        if self.clamp.at and line.kind != "shift":
            self.clamp.interrupted()
        TAKERS[line.kind](self, number, line)

    def finish(self) -> None:
        self.clamp.interrupted()

    def _header(self, number: int, line) -> None:
        places = {"first": number == 1, "second": number == 2, "last": number == self.count}
        if not any(places[place] for place in line.places):
            raise Refused(f"the {line.what} belongs only in the {' or '.join(sorted(line.places))} line")

    def _comment(self, number: int, line) -> None:
        return None

    def _block(self, number: int, block) -> None:
        if block.area:
            self._set_area(block)
        elif block.moves:
            self._check_motion(block.positions)
            if block.motion in ARCS:
                self._check_arc(block)
            self.position.update(block.positions)
        if block.speed is not None:
            self._set_speed(block.speed)
        if block.facts:
            self.facts |= block.facts
            self.ready = self.dialect.motion_needs <= self.facts

    def _set_area(self, block) -> None:
        for axis, value in block.positions.items():
            low, high = self.travel[axis]
            if not low <= value <= high:
                check_travel(axis, value, self.machine, "working-area limit ")
        self.area[block.area] = dict(block.positions)
        lower, upper = self.area["lower"], self.area["upper"]
        self.bounds = {axis: (max(low, lower.get(axis, -math.inf)), min(high, upper.get(axis, math.inf)))
                       for axis, (low, high) in self.travel.items()}

    def _check_motion(self, positions: dict) -> None:
        if not self.ready:
            raise Refused(self.dialect.motion_needs_reason)
        bounds = self.bounds
        for axis, value in positions.items():
            low, high = bounds[axis]
            if not low <= value <= high:
                self._refuse_position(axis, value)

    def _refuse_position(self, axis: str, value: float) -> None:
        check_travel(axis, value, self.machine)
        low, high = self.area["lower"].get(axis), self.area["upper"].get(axis)
        raise Refused(f"{axis}{value:g} lies outside the working area G25/G26 {axis} {low:g}…{high:g}")

    def _check_arc(self, block) -> None:
        if not {"X", "Z"} <= self.position.keys():
            raise Refused("an arc from an unknown start point: program X and Z before it")
        end = {**self.position, **block.positions}
        box = arc_box(self.position["X"], self.position["Z"], end["X"], end["Z"],
                      block.values[self.dialect.arc_radius], block.motion == 3)
        for axis, extremes in box.items():
            for extreme in extremes:
                check_travel(axis, extreme, self.machine, "the arc reaches ")

    def _set_speed(self, speed: float) -> None:
        check_spindle(speed, self.machine)
        self.speed = speed
        self._check_table()

    def _check_table(self) -> None:
        if self.speed is not None and self.ratio is not None:
            check_table(self.speed, self.ratio, self.machine)

    def _statement(self, number: int, statement) -> None:
        STATEMENT_TAKERS[statement.name](self, statement)

    def _define_coupling(self, statement) -> None:
        self.coupled_axes = statement.leading

    def _couple(self, statement) -> None:
        if statement.leading != self.coupled_axes:
            raise Refused(f"EGON couples {','.join(statement.leading)} but EGDEF defined "
                          f"{','.join(self.coupled_axes or ()) or 'nothing'}")
        self.ratio = statement.ratio
        self._check_table()

    def _uncouple(self, statement) -> None:
        self.ratio = None

    def _delete_coupling(self, statement) -> None:
        self.coupled_axes = self.ratio = None

    def _shift(self, number: int, line) -> None:
        ends = self.clamp.take(line)
        if ends is not None:
            for value in ends:
                self._check_motion({"Y": value})


TAKERS = {"header": Walk._header, "comment": Walk._comment, "block": Walk._block,
          "statement": Walk._statement, "shift": Walk._shift}
STATEMENT_TAKERS = {"EGDEF": Walk._define_coupling, "EGON": Walk._couple, "EGOFS": Walk._uncouple,
                    "EGDEL": Walk._delete_coupling}
