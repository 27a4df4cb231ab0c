"""The lathe program followed block by block as the control runs it: the tool's position (X a
diameter, turned into the radius r = X/2 of the (z, r) half-plane), the spindle, the feed
mode, the operation the block belongs to, and every tool change. What refuses here needs no
geometry of the material: a tool change away from the job's tool-change position or in a block
that moves (the turret swings its tools out there: anywhere else one of them hits the part or
the chuck), a cut with the spindle stopped or turning against the tool (the templates' outside
tools cut with M03, design notes §8), a thread pass in an operation that is not a THREAD, an
operation comment, a tool word or a tool offset (ISO T0101's last digits, 840D D) that is not
the job's. Each motion is handed on as a Move for the material walk.

A class job (records.drawn False: no drawing record) has no tool-change position, no operations
and no tools: a program starts at the machine's reference point (`start`), each tool change is
kept as a ToolChange for the check against the blank's envelope (engine.simulation.turning.
undrawn), and a cut needs the spindle turning, M03 or M04 (which direction a tool cuts in is an
operation record's). A reference return (ISO/LinuxCNC G28, G30; 840D G74, G75) runs at rapid to
its intermediate point, if the block gives one, and on to the reference point."""
from __future__ import annotations

import math

import msgspec

from ...verifier.arcs import arc_centre
from .report import TurningReport
from .work import Point, TurningRecords, arc_points

RAPID, FEED, THREAD = "rapid", "feed", "thread"
MOTIONS = {0: RAPID, 1: FEED, 2: FEED, 3: FEED, 32: THREAD, 33: THREAD}
CUTTING_DIRECTION = 3        # M03: the direction the templates' outside turning tools cut in
TOOL_CHANGE_TOLERANCE_MM = 0.01
DEFAULT_EDGE = 1            # 840D: D1 with a new tool unless the block says otherwise
PER_MINUTE, PER_REVOLUTION = (94, 98), (95, 99)   # 840D G94/G95, ISO G98/G99
# The G codes that send the turret to the machine's reference point (or a fixed point beside it),
# per dialect: ISO (Fanuc/Haas) and LinuxCNC G28/G30, Sinumerik 840D G74/G75.
REFERENCE_RETURNS = {"iso": frozenset({28, 30}), "linuxcnc": frozenset({28, 30}), "840d": frozenset({74, 75})}


class Move(msgspec.Struct, frozen=True):
    number: int
    line: str
    kind: str                 # rapid, feed or thread
    points: list[Point]       # (z, r) along the move, start first
    operation: int | None
    speed: float | None       # S in r/min (G97), or m/min under G96
    constant_speed: bool      # G96
    feed: float | None        # F as written
    per_minute: bool          # G94/G98
    lead: float | None        # a thread's lead, mm/rev
    blend: float = 0.0        # mm the control may run it off its path (LinuxCNC G64 P; material walk)


class ToolChange(msgspec.Struct, frozen=True):
    """A tool change of a class job, where the turret indexed: (z, r), and whether at the reference point."""
    number: int
    line: str
    point: Point
    at_reference: bool


class ProgramState:
    def __init__(self, records: TurningRecords, report: TurningReport, dialect: str, start: tuple[float, float]):
        """`start`: (x diameter, z) where the turret stands when the program starts: the job's
        tool-change position (where the last program left it), or for a class job the reference point."""
        self.records, self.report, self.iso = records, report, dialect == "iso"
        self.returns = REFERENCE_RETURNS.get(dialect, frozenset())
        self.reference = start
        self.x, self.z = start
        self.at_reference = not records.drawn   # a class job: the turret at the reference point
        self.changes: list[ToolChange] = []
        self.spindle: int | None = None  # 3, 4 or None (stopped)
        self.speed: float | None = None
        self.constant_speed = False
        self.feed: float | None = None
        self.per_minute = True
        self.motion: int | None = None
        self.operation: int | None = None
        self.moves: list[Move] = []

    def take(self, step) -> None:
        if step.operation is not None:
            self._operation(step)
        if step.block is None:
            return
        self._modes(step)
        if step.g_codes & self.returns:
            self._reference_return(step)
            return
        if "T" in step.block.values:
            self._tool_change(step)
        elif not self.iso and "D" in step.block.values:
            self._offset(step, _whole_word(step.block.values["D"]))
        if step.block.motion is not None:
            self.motion = step.block.motion
        if step.block.moves and self.motion in MOTIONS:
            self._move(step)

    def _reference_return(self, step) -> None:
        """At rapid through the block's X/Z (the intermediate point), then to the reference point."""
        block = step.block
        through = (block.positions.get("X", self.x), block.positions.get("Z", self.z))
        for x, z in (through, self.reference):
            start = (self.z, self.x / 2.0)
            self.x, self.z = x, z
            self.moves.append(Move(step.number, step.line, RAPID, [start, (z, x / 2.0)], self.operation, self.speed,
                                   self.constant_speed, self.feed, self.per_minute, None, step.blend))
        self.at_reference = True

    def _operation(self, step) -> None:
        if not self.records.drawn:
            return   # a class job has no operation records to hold a comment against
        n, kind = step.operation
        known = self.records.operations.get(n)
        if known is None or known.kind != kind:
            said = "no such operation" if known is None else f"operation {n} is {known.kind}"
            self.report.add(step.number, step.line, f"the comment names operation {n} {kind}, but the job's "
                            f"records say {said}: the simulation cannot tell what this part of the program cuts")
            self.operation = None
            return
        self.operation = n

    def _modes(self, step) -> None:
        block, g, m = step.block, step.g_codes, step.m_codes
        if block.speed is not None:
            self.speed = block.speed
        self.constant_speed = (self.constant_speed or 96 in g) and 97 not in g
        if g & set(PER_MINUTE) or g & set(PER_REVOLUTION):
            self.per_minute = bool(g & set(PER_MINUTE))
        if block.feed is not None:
            self.feed = block.feed
        if m & {3, 4}:
            self.spindle = 3 if 3 in m else 4
        if 5 in m or 30 in m:
            self.spindle = None

    def _tool_change(self, step) -> None:
        block = step.block
        if block.moves:
            self.report.add(step.number, step.line, "a tool change in a block that moves: the turret indexes "
                            "on the way, not at the tool-change position; write T in its own block there")
        x, z = block.positions.get("X", self.x), block.positions.get("Z", self.z)
        if self.records.tool_change is None:   # a class job: checked against the blank once it is known
            self.changes.append(ToolChange(step.number, step.line, (z, x / 2.0), self.at_reference and not block.moves))
            return
        want_x, want_z = self.records.tool_change
        if abs(x - want_x) > TOOL_CHANGE_TOLERANCE_MM or abs(z - want_z) > TOOL_CHANGE_TOLERANCE_MM:
            self.report.add(step.number, step.line, f"a tool change at X{x:.3f} Z{z:.3f}, away from the job's "
                            f"tool-change position X{want_x:.3f} Z{want_z:.3f} (params.tool_change_x/_z): "
                            "the turret swings its tools there only")
        tool = _tool_number(block.values["T"], self.iso)
        op = self._current()
        if op is not None and op.tool is not None and tool != op.tool:
            self.report.add(step.number, step.line, f"tool {tool} in operation {op.number}, whose tool is "
                            f"{op.tool} (module_params.prep:{op.number}.tool)")
        self._offset(step, _offset_number(block.values, self.iso))

    def _offset(self, step, offset: int) -> None:
        """The tool offset the block activates against the operation's (module_params.prep:n.tool_offset):
        another offset moves every cut of the operation by the difference of the two offsets' wear
        and geometry values, which the program cannot show."""
        op = self._current()
        if op is not None and op.offset is not None and offset != op.offset:
            word = "the T word's last two digits" if self.iso else "D"
            self.report.add(step.number, step.line, f"tool offset {offset} ({word}) in operation {op.number}, "
                            f"whose offset is {op.offset} (module_params.prep:{op.number}.tool_offset)")

    def _current(self):
        return self.records.operations.get(self.operation) if self.operation else None

    def _move(self, step) -> None:
        block, motion = step.block, self.motion
        assert motion is not None   # take() moves only with a motion in force
        start = (self.z, self.x / 2.0)
        self.x, self.z = block.positions.get("X", self.x), block.positions.get("Z", self.z)
        end = (self.z, self.x / 2.0)
        self.at_reference = self.at_reference and start == end
        kind = MOTIONS[motion]
        points = [start, end]
        if motion in (2, 3):
            radius = block.values.get("R", block.values.get("CR"))
            if radius is not None and math.dist(start, end) > 0:
                points = arc_points(start, end, arc_centre(start, end, radius, motion == 3), motion == 3)
        lead = block.values.get("K", block.values.get("F")) if kind == THREAD else None
        if kind != RAPID:
            self._check_cut(step, kind)
        self.moves.append(Move(step.number, step.line, kind, points, self.operation, self.speed,
                               self.constant_speed, self.feed, self.per_minute, lead, step.blend))

    def _check_cut(self, step, kind: str) -> None:
        what = "a thread pass" if kind == THREAD else "a cut"
        if self.spindle is None:
            self.report.add(step.number, step.line, f"{what} with the spindle stopped (no M03 or M04 since the "
                            "start or the last M05): the tool is driven into a standing part")
        elif self.spindle != CUTTING_DIRECTION and self.records.drawn:
            self.report.add(step.number, step.line, f"{what} with the spindle turning M0{self.spindle}: the "
                            f"job's outside turning tools cut with M0{CUTTING_DIRECTION}")
        op = self._current()
        if op is None and self.records.drawn:
            self.report.add(step.number, step.line, f"{what} outside any of the job's operations (no "
                            "operation comment OP n KIND before it): the simulation cannot tell what it may cut")
        elif op is not None and kind == THREAD and op.kind != "THREAD":
            self.report.add(step.number, step.line, f"{what} in operation {op.number} {op.kind}: threads are cut "
                            "only in a THREAD operation, along the drawn thread")


def _tool_number(value: float, iso: bool) -> int:
    """ISO T0707: tool 7, offset 7 (reference §E); 840D T7 with its D word apart."""
    return int(value) // 100 if iso else int(value)


def _offset_number(values: dict[str, float], iso: bool) -> int:
    """ISO T0709: offset 9, T0700 cancels it (0; reference §E). 840D `T7 D9`: D9; `T7` alone: the
    edge the control activates with a new tool, D1 (Sinumerik MD20270 $MC_CUTTING_EDGE_DEFAULT = 1
    as delivered)."""
    if iso:
        return int(values["T"]) % 100
    return _whole_word(values.get("D", DEFAULT_EDGE))


def _whole_word(value: float) -> int:
    return int(value) if float(value).is_integer() else -1
