"""The moves the simulation follows, kept for a picture (`engine plot`, issue 17): the same
reading and the same walk as `engine simulate` (engine.simulation.hobbing.run), with every move's start
and end in the DIN frame, the swivel it ran at, whether it cut, the cuts as the walk closes them
and the G25/G26 working area as the program sets it. A picture drawn from this shows what the
simulation checked, not a second interpretation of the program text: the F in effect at each
move, each A as the program writes it and each coupling are kept too (the numbers a picture
states, issue 27), the coupling with its start as the program writes it: read in the machine's
dialect, an 840D `EGON(…)` or a Fanuc `G81 T… L…` (issue 30). A program with the
hob-shift-per-part clamp is followed at both ends of its R11 (#500) interval (the Y range it cuts at,
the part of the hob the shifting uses); the moves are those at the low end."""
from __future__ import annotations

import re

import msgspec

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...machines.work_holding import WorkHolding
from .fanuc_egb import refuse_unproved_compensation
from .reading import read_program
from .report import Report, SimulationError
from .run import SHIFT_ENDS
from .solids import Solid, setup_solids, unit_solids
from .walk import BlockSimulation

SWIVEL_EQUALS = re.compile(r"(?<![A-Z])A=")   # `A=1.763` (840D) rather than `A1.763` (840D, ISO, Fanuc)


class Move(msgspec.Struct, frozen=True):
    number: int            # program line, from 1
    line: str
    motion: int            # 0 rapid, 1 feed
    start: dict            # DIN positions before the move (axes not yet known are missing)
    end: dict
    swivel: float          # A in the DIN frame, degrees
    cutting: bool          # part of a cut the walk follows (coupled, spindle turning, G1)
    feed: float | None = None   # the F in effect, as written (mm/min: the hobbing grammar has G94 only)


class RecordedCut(msgspec.Struct, frozen=True):
    moves: tuple           # the cut's Move records
    units: tuple           # names of the units whose material it entered
    label: str             # the program's `; CUT …` comment before it, else "cut N"

    @property
    def poses(self) -> list[dict]:
        """Where the hob centre stands along the cut, from its start: the poses with X and Z known."""
        every = [self.moves[0].start, *(move.end for move in self.moves)]
        return [pose for pose in every if {"X", "Z"} <= pose.keys()]


class Recording(msgspec.Struct):
    report: Report
    units: list[Solid]
    setup: list[Solid]
    moves: list[Move] = []
    cuts: list[RecordedCut] = []
    areas: dict = {}       # "lower"/"upper" -> {axis: DIN value}, as G25/G26 set them
    area_words: dict = {}  # "lower"/"upper" -> {axis: program value}
    cutting_y: tuple = (0.0, 0.0)                   # the lowest and highest Y (DIN) the hob cuts at
    swivel_words: list = []     # (line, A as written) for every A the program writes
    couplings: list = []        # every EGON (G81) as the walk read it (DIN Coupling)
    coupling_words: list = []   # each coupling's start as the program writes it
    swivel_address: str = "A"   # how it writes the swivel: `A=` (840D templates) or `A`

    @property
    def final_swivel(self) -> float:
        return next((move.swivel for move in reversed(self.moves) if move.cutting), 0.0)


class RecordingSimulation(BlockSimulation):
    """The simulation's walk, keeping what it follows."""

    def __init__(self, recording: Recording, *args):
        super().__init__(*args)
        self.recording = recording
        self.cut_moves: list[Move] = []
        self.last_comment = ""

    def take(self, step) -> None:
        """The walk dispatches by the line's kind; what a picture needs is noted first."""
        if step.kind == "comment":
            self.last_comment = step.line.lstrip("; ").strip()
        elif step.kind == "block" and step.item.area is not None:
            self._note_area(step.item)
        super().take(step)

    def _note_area(self, block) -> None:
        self.recording.area_words[block.area] = dict(block.positions)
        self.recording.areas[block.area] = {axis: self.senses.position(axis, value)
                                            for axis, value in block.positions.items()}

    def _couple(self, step) -> None:
        super()._couple(step)
        self.recording.couplings.append(self.coupling)
        self.recording.coupling_words.append(step.line.partition(";")[0].strip())

    def _move(self, step, motion: int, program: dict, swivel: float | None = None) -> None:
        start = dict(self.position)
        if swivel is not None:
            self.recording.swivel_words.append((step.number, swivel))
            self.recording.swivel_address = "A=" if SWIVEL_EQUALS.search(step.line.partition(";")[0]) else "A"
        super()._move(step, motion, program, swivel)
        move = Move(step.number, step.line, motion, start, dict(self.position), self.swivel, self.cut is not None,
                    self.feed)
        self.recording.moves.append(move)
        if move.cutting:
            self.cut_moves.append(move)

    def _end_cut(self) -> None:
        before = len(self.report.cuts)
        super()._end_cut()
        if self.cut_moves:
            units = tuple(done.unit for done in self.report.cuts[before:])
            label = self.last_comment if self.last_comment.upper().startswith("CUT") else \
                f"cut {len(self.recording.cuts) + 1}"
            self.recording.cuts.append(RecordedCut(tuple(self.cut_moves), units, label))
            self.cut_moves = []


def record_program(lines: list[str], gear: Gear, hob: Hob, machine: Machine, name: str = "the program",
                   holding: WorkHolding | None = None) -> Recording:
    """The recording of `lines` (a hobbing program for `gear`, `hob`, `machine`); SimulationError
    for a program or machine the simulation cannot read."""
    if machine.kind != "hobber":
        raise SimulationError(f"machine {machine.name} is a {machine.kind}: the simulation follows hobbing programs")
    steps = read_program(lines, machine, name)
    refuse_unproved_compensation(steps, gear, machine, name)   # Fanuc Q/P: fanuc-egb.md §F5
    ends = SHIFT_ENDS if any(step.kind == "shift" for step in steps) else SHIFT_ENDS[:1]
    recordings = [_follow(steps, lines, gear, hob, machine, name, end, holding) for end in ends]
    held = [pose["Y"] for recording in recordings for move in recording.moves if move.cutting
            for pose in (move.start, move.end) if "Y" in pose]
    recording = recordings[0]
    recording.cutting_y = (min(held), max(held)) if held else (0.0, 0.0)
    return recording


def _follow(steps, lines, gear: Gear, hob: Hob, machine: Machine, name: str, shift_end: int,
            holding: WorkHolding | None = None) -> Recording:
    worm_wheel = hob.purpose == "worm_wheel"
    units = unit_solids(gear, hob, worm_wheel)
    setup = setup_solids(machine, units, hob, holding)
    recording = Recording(Report(name), units, setup)
    walk = RecordingSimulation(recording, recording.report, gear, hob, machine, units, setup, worm_wheel, shift_end)
    for step in steps:
        walk.take(step)
    walk.finish(lines)
    return recording
