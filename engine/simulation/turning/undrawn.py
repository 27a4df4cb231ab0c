"""What the turning simulation proves of a class job's program (`engine instantiate --class`: a
shop's own program, no drawing record) and what it cannot (design notes §8).

Proved, from the program and the job's params: the blank (the one params.stock_diameter,
stock_z_front and stock_z_back state, or else the one the program implies: its largest feed
radius over the Z range it feeds, marked "(assumed)"); no rapid through material not cut yet
(engine.simulation.turning.material); no cut or thread pass with the spindle stopped
(engine.simulation.turning.follow); no tool change in a block that moves, nor with the tool
inside the blank's envelope: without a tool-change position record the turret must index clear
of the material, outside the blank's radius or in front of its front face, or at the reference
point (a program starts there; a reference return brings the turret back). A thread's lead × S
against the machine's feed is the verifier's (engine.verifier).

Not proved, and said in the report (TurningReport.not_checked): cuts into the finished part,
the operations, tools, tool offsets and spindle direction, and the cutting data, all of which
need a drawing record."""
from __future__ import annotations

from shapely.geometry import box
from shapely.geometry.base import BaseGeometry

from ...machines.records import Machine
from .follow import RAPID, Move, ToolChange
from .report import TurningReport

CLEAR_MM = 0.01    # the turret indexes clear of the blank by more than the program's rounding

NOT_CHECKED = (
    "a cut into the finished part (no drawing record: no part)",
    "the operations, their tools, tool offsets and spindle direction (no drawing record: no operation records)",
    "feeds and cutting speeds against the cutting-data table (no drawing record: no materials)",
    "a thread's lead against a drawn pitch (no drawing record; its lead × S is the verifier's)",
    "the tool-change position (no drawing record): a tool change is held against the blank's envelope",
)


def reference_point(machine: Machine) -> tuple[float, float]:
    """(x diameter, z) of the lathe's reference point, where a reference return sends the turret:
    the record's (reference_x, reference_z, in the travel's frame) when stated, else the far corner
    of its travel, X max and Z max, away from the chuck, as the verifier's travel limits give it."""
    if machine.reference_x is not None and machine.reference_z is not None:
        return float(machine.reference_x), float(machine.reference_z)
    return machine.x_max, machine.z_max


def program_blank(moves: list[Move], stock: tuple[float, float, float] | None) -> tuple[BaseGeometry, bool]:
    """(the blank, whether assumed): the stated one, or the program's largest feed radius over the
    Z range its feeds and thread passes cover (both sides of the axis); empty without any."""
    if stock is not None:
        z_front, z_back, radius = stock
        return box(z_back, -radius, z_front, radius), False
    points = [point for move in moves if move.kind != RAPID for point in move.points]
    if not points:
        return box(0.0, 0.0, 0.0, 0.0), True
    zs, radius = [z for z, _ in points], max(r for _, r in points)
    return box(min(zs), -radius, max(zs), radius), True


def check_tool_changes(changes: list[ToolChange], blank: BaseGeometry, report: TurningReport) -> None:
    """A tool change with the tool inside the blank's envelope (r up to its radius, Z behind its
    front face) is refused: the turret swings its other tools through the material there."""
    _, _, z_front, radius = blank.bounds
    for change in changes:
        z, r = change.point
        if change.at_reference or r > radius + CLEAR_MM or z > z_front + CLEAR_MM or blank.area == 0:
            continue
        report.add(change.number, change.line, f"a tool change at X{2 * r:.3f} Z{z:.3f}, inside the blank's "
                   f"envelope (Ø{2 * radius:.3f}, front face Z{z_front:.3f}): without a tool-change position "
                   "record the turret indexes only clear of the material, outside the blank's diameter, in "
                   "front of its face or after a reference return")
