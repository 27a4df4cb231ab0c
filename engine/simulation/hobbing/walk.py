"""The block-by-block walk: every axis (X, Y, Z, A; C through the coupling) followed in the DIN
frame, each move's hob poses (engine.simulation.hobbing.paths) checked against the solids, the coupling
and swivel checked where the hob cuts, cuts collected, the table speed and cycle time summed.

M codes whose timing against the block's motion is the machine builder's choice are taken the
unsafe way round: the spindle counts as turning (M3) and the tailstock as released (M21) only
after the block's motion, as stopped (M5) and clamped (M20) already during it."""
from __future__ import annotations

import math

from ...gears.records import Gear, Hob
from ...machines.records import Machine
from ...verifier.refusals import Refused
from ...verifier.shift_clamp import ShiftClamp
from .allowance import depth_problem, header_allowance
from .contact import Motion, follow
from .coupling import (
    COUPLING_OFF,
    COUPLING_ON,
    Coupling,
    coupling_problems,
    generated_teeth_problem,
    hand_name,
    hand_sign,
    helix_of,
    lead_angle,
    swivel_problem,
)
from .cuts import Cut, summary
from .envelope import HobBody
from .fanuc_egb import read_start
from .frame import Senses
from .headers import comment_problem, header_place_problem
from .paths import move_pieces
from .report import Report, SimulationError, where
from .rules import (
    block_record_problem,
    coupled_shift_problem,
    coupled_swivel_problem,
    coupled_tool_problem,
    feed_problem,
    least_run_out,
    moves,
    record_header_problem,
    recut_problem,
    run_out_problem,
    setup_advice,
    zone_problem,
)
from .solids import Solid
from .swivel_sweep import sweep_problem, unknown_pose
from .timing import feed_minutes, header_minutes, header_problem, rapid_minutes

AXES = ("X", "Y", "Z")
MAX_SWIVEL = 80.0        # degrees from horizontal the hob axis may stand (helix angles stay well below)


class BlockSimulation:
    """One hobbing program followed block by block: the axes, the hob's poses against the solids,
    the coupling, the cuts, the table speed and the cycle time, each problem into the report."""

    def __init__(self, report: Report, gear: Gear, hob: Hob, machine: Machine, units: list[Solid],
                 setup: list[Solid], worm_wheel: bool, shift_end: int):
        self.report, self.gear, self.hob, self.machine = report, gear, hob, machine
        self.units, self.solids, self.worm_wheel, self.shift_end = units, units + setup, worm_wheel, shift_end
        self.senses = Senses.of(machine)
        self.body = HobBody(hob.tip_diameter / 2, hob.length / 2)
        load_x, load_z = machine.load_x, machine.load_z
        self.program = {"X": load_x, "Z": load_z} if load_x is not None and load_z is not None else {}   # for time
        self.position = {axis: self.senses.position(axis, value) for axis, value in self.program.items()}
        self.swivel = 0.0
        self.swivel_known = False
        self.feed = self.speed = None
        self.spindle = self.tailstock = False
        self.coupling: Coupling | None = None
        self.session = 0
        self.cut: Cut | None = None
        self.last_cut_of: dict[int, Cut] = {}
        self.clamp = ShiftClamp()
        self.said: set = set()
        self.allowance = 0.0
        self.allowance_stated = self.moved = False

    # ---------------------------------------------------------------- lines

    def take(self, step) -> None:
        self._refuse(step, comment_problem(step))
        TAKERS[step.kind](self, step)

    def _comment(self, step) -> None:
        minutes = header_minutes(step.line)
        if minutes is not None:
            self._refuse(step, header_place_problem("CYCLE TIME", self.report.header_time is not None, self.moved))
            self.report.header_time = minutes
            self.header_step = step
        allowance = header_allowance(step.line)
        if allowance is not None:
            self._refuse(step, header_place_problem("ALLOWANCE", self.allowance_stated, self.moved))
            self.allowance, self.allowance_stated = allowance, True
        self._refuse(step, record_header_problem(step.line, self.gear, self.hob, self.machine))

    def _refuse(self, step, problem: str | None) -> None:
        if problem:
            self.report.add(step.number, step.line, problem)

    def _header(self, step) -> None:
        return None

    def _statement(self, step) -> None:
        self._end_cut()
        if step.item.name in COUPLING_ON:
            self._couple(step)
        elif step.item.name in COUPLING_OFF:
            self.coupling = None

    def _couple(self, step) -> None:
        self.coupling = read_start(step.item, step.line.partition(";")[0].strip(), self.senses, self.machine)
        self.session += 1
        teeth = [unit.teeth for unit in self.units if unit.teeth is not None]   # every unit is toothed
        problem = generated_teeth_problem(self.coupling, self.hob, teeth)
        if problem:
            self.report.add(step.number, step.line, problem)
        self._describe_coupling(self.coupling)

    def _describe_coupling(self, coupling: Coupling) -> None:
        teeth = coupling.teeth(self.hob.starts)
        self.report.teeth.append(f"{teeth:g}")
        if self.worm_wheel:
            beta = lead_angle(self.hob) * hand_sign(self.hob.hand) - self.swivel
            side = "R" if beta >= 0 else "L"
            self.report.helix.append(f"{hand_name(side)} β {abs(beta):.3f}° (hob lead and swivel)")
            return
        beta, hand, lead = helix_of(coupling.factors.get("Z", 0.0), self.gear, round(teeth) or 1)
        self.report.helix.append("spur" if hand is None else f"{hand_name(hand)} β {beta:.3f}° lead {lead:.1f} mm")

    def _shift(self, step) -> None:
        try:
            ends = self.clamp.take(step.item)
        except Refused as refusal:
            raise SimulationError(f"{where(self.report.name, step.number, step.line)}: {refusal}") from None
        if ends is not None:
            self._move(step, 0, {"Y": ends[self.shift_end]})

    def _block(self, step) -> None:
        block = step.item
        self._refuse(step, block_record_problem(step, self.hob, self.machine))
        if self.coupling is not None:
            self._refuse(step, coupled_tool_problem(block.values))
        if 5 in step.m_codes or "SPOS" in block.values:    # SPOS stops the spindle to position it
            self.spindle = False
        if 20 in step.m_codes:
            self.tailstock = True
        if block.feed is not None:
            self.feed = block.feed
        if block.speed is not None:
            self.speed = block.speed
        if block.dwell is not None:
            self.report.cycle_time += block.dwell / 60.0
        elif block.moves and block.area is None:
            self.moved = True
            self._move(step, block.motion, dict(block.positions), block.values.get("A"))
        if 3 in step.m_codes:
            self.spindle = True
        if 21 in step.m_codes:
            self.tailstock = False

    # ---------------------------------------------------------------- moves

    def _move(self, step, motion: int, program: dict, swivel: float | None = None) -> None:
        if self.coupling is not None:
            self._check_coupled_axes(step, program, swivel)
        swivelling = swivel is not None and (not self.swivel_known or
                                             moves({"A": self.swivel}, "A", self.senses.swivel(swivel)))
        swivel_from = self.swivel if self.swivel_known else None
        if swivel is not None:
            self.swivel, self.swivel_known = self.senses.swivel(swivel), True
        target = {axis: self.senses.position(axis, value) for axis, value in program.items()}
        start = dict(self.position)
        end = {**start, **target}
        self._time(motion, program)
        cutting = motion == 1 and self.coupling is not None and self.spindle and (self.speed or 0) > 0
        velocities = self._velocities(motion, start, end)
        self._table_speed(step, velocities)
        if cutting:
            self._check_cut(step, start, end)
            self._extend_cut(step, start, end, velocities)
        else:
            self._end_cut()
        if {"X", "Z"} <= end.keys():
            if unknown_pose(swivelling, self.swivel_known, self.swivel, end):
                self._swivel_sweep(step, start, end, swivel_from)
            self._contacts(step, motion, cutting, start, end, swivelling)
        self.position = end

    def _swivel_sweep(self, step, start: dict, end: dict, swivel_from: float | None) -> None:
        self._refuse(step, sweep_problem(self.solids, self.body, self.tailstock, start, end, swivel_from,
                                         self.swivel, max(abs(self.machine.y_min), abs(self.machine.y_max))))

    def _check_coupled_axes(self, step, program: dict, swivel: float | None) -> None:
        """Y (unless a leading axis) and A may not move while the table is coupled (§B15)."""
        if "Y" in program and moves(self.position, "Y", self.senses.position("Y", program["Y"])):
            self._refuse(step, coupled_shift_problem(self.coupling))
        swivels = swivel is not None and (not self.swivel_known or
                                          moves({"A": self.swivel}, "A", self.senses.swivel(swivel)))
        if swivels:
            self._refuse(step, coupled_swivel_problem())

    def _time(self, motion: int, program: dict) -> None:
        if motion == 0:
            self.report.cycle_time += rapid_minutes(self.program, program, self.machine.rapid_rate)
        elif self.feed:
            self.report.cycle_time += feed_minutes(self.program, program, self.feed)
        self.program.update(program)

    def _velocities(self, motion: int, start: dict, end: dict) -> dict:
        delta = {axis: end[axis] - start[axis] for axis in AXES if axis in end and axis in start
                 and abs(end[axis] - start[axis]) > 1e-9}
        if motion == 0:
            return {axis: math.copysign(self.machine.rapid_rate, value) for axis, value in delta.items()}
        length = math.sqrt(sum(value * value for value in delta.values()))
        rate = self.feed or 0.0
        return {axis: rate * value / length for axis, value in delta.items()} if length else {}

    def _table_speed(self, step, velocities: dict) -> None:
        """n_C = k_B·n_B + (k_Z·v_Z + k_Y·v_Y)/360 (reference §A5), program values and senses."""
        if self.coupling is None:
            return
        factors = self.coupling.program_factors
        turning = self.speed if self.spindle and self.speed else 0.0
        program_v = {axis: v * {"X": 1, "Y": self.senses.y, "Z": self.senses.z}[axis] for axis, v in velocities.items()}
        speed = abs(factors["B"] * turning + sum(factors.get(axis, 0.0) * program_v.get(axis, 0.0)
                                                 for axis in ("Z", "Y")) / 360.0)
        self.report.table_speed = max(self.report.table_speed, speed)
        limit = self.machine.table_speed_max
        if limit is not None and speed > limit + 1e-9:
            self.report.add(step.number, step.line,
                            f"the table turns at {speed:.1f} r/min, above {self.machine.name}'s "
                            f"{limit:g} r/min (hob, Z and Y terms at this move's speeds)")

    def _check_cut(self, step, start: dict, end: dict) -> None:
        moving = frozenset(axis for axis in AXES if axis in start and abs(end[axis] - start[axis]) > 1e-9)
        teeth = self._cut_teeth()
        problems: list[str | None] = []   # None: no problem
        if "Y" not in self.position:
            problems.append("Y (the hob shift) is not positioned before the cut: the generating zone lies "
                            "wherever the last program left the hob")
        if not self.swivel_known:
            problems.append("the swivel A is not positioned before the cut")
        else:
            problems.append(swivel_problem(self.swivel, self.gear, self.hob))
        if "Y" in self.position and not self.worm_wheel:
            problems.append(zone_problem(self.position["Y"], self.gear, self.hob))
        if teeth is not None:
            problems += coupling_problems(self._coupled, self.gear, self.hob, teeth, self.worm_wheel, moving)
        for problem in filter(None, problems):
            if (self.session, problem) not in self.said:
                self.said.add((self.session, problem))
                self.report.add(step.number, step.line, problem)

    @property
    def _coupled(self) -> Coupling:
        """The coupling, where the walk cuts (a cut is one only while the table is coupled)."""
        assert self.coupling is not None
        return self.coupling

    def _cut_teeth(self) -> int | None:
        teeth = self._coupled.teeth(self.hob.starts)
        return int(round(teeth)) if abs(teeth - round(teeth)) < 1e-9 else None

    def _contacts(self, step, motion: int, cutting: bool, start: dict, end: dict, swivelling: bool) -> None:
        """The hob's contacts on the move, at the swivel it ends with. A move that swivels the hob
        is followed at its new A at the sampled poses and heights only (not a translation:
        contact_bounds' convexity does not hold on it); the swivel between its ends is proved by
        _swivel_sweep (engine.simulation.hobbing.swivel_sweep), or refused."""
        swivel = (self.swivel + 90.0) % 180.0 - 90.0       # a cylinder turned by 180° is the same cylinder
        if abs(swivel) > MAX_SWIVEL:
            self.report.add(step.number, step.line, f"the swivel A {self.swivel:g}° sets the hob axis within "
                                                    f"{90 - MAX_SWIVEL:g}° of the work axis: not a hobbing set-up")
            return
        if round((self.swivel - swivel) / 180.0) % 2:   # the head turned half a turn: the same cylinder,
            start, end = _along_flipped_axis(start), _along_flipped_axis(end)   # its shift the other way
        pieces = move_pieces(start, end, motion == 0)
        teeth = self._cut_teeth() if cutting else None
        reason = self._reason(motion)
        running = self.coupling is not None and self.spindle and not _rapid_along_z(motion, start, end)
        for contact in follow(self.solids, self.body, swivel, pieces,
                              Motion(teeth, running, self.session, self.tailstock, reason, swivelling)):
            self.report.add(step.number, step.line, self._contact_message(contact, reason, teeth))
        for unit in self.units:
            if len(unit.cut_sessions) > 1 and ("recut", unit.name) not in self.said:
                self.said.add(("recut", unit.name))
                self._refuse(step, recut_problem(unit.name, self.coupling.command if self.coupling else "EGON"))

    def _reason(self, motion: int) -> str:
        if motion == 0:
            return "on a rapid move (G0)"
        if self.coupling is None:
            return "feeding with the table not coupled to the hob"
        if not (self.spindle and self.speed):
            return "feeding with the hob spindle stopped"
        return f"feeding with a coupling that generates {self.coupling.teeth(self.hob.starts):g} teeth"

    def _contact_message(self, contact, reason: str, teeth) -> str:
        z = contact.height * self.senses.z
        if contact.below_root:
            return (f"the hob cuts {contact.depth:.3f} mm below the intended root of {contact.solid.name} at Z{z:.3f}")
        return (f"the hob runs {contact.depth:.3f} mm into {contact.solid.name} at Z{z:.3f} {reason}"
                f"{setup_advice(contact.solid.name)}")

    def _extend_cut(self, step, start: dict, end: dict, velocities: dict) -> None:
        teeth = self._cut_teeth()
        if teeth is None:
            return
        assert self.speed is not None   # a cut is one only with the spindle turning at an S above 0
        if self.cut is None or self.cut.teeth != teeth:
            self._end_cut()
            table = abs(self._coupled.k_b) * self.speed
            before = {id(unit): list(unit.reach) for unit in self.units if unit.teeth == teeth}
            self.cut = Cut(step.number, step.line, teeth, table, before)
        self.cut.add(start, end, velocities)
        table = abs(self._coupled.k_b) * self.speed        # the spindle speed now, not the cut's first
        along, motion = ("Y", "tangential pass") if self.worm_wheel else ("Z", "pass")   # §C bounds both passes
        if table > 0 and velocities.get(along):
            self._refuse(step, feed_problem(abs(velocities[along]) / table, self.gear, self.hob, motion))
        if table > 0 and velocities.keys() == {"X"}:          # the radial infeed is bounded by §C too
            self._refuse(step, feed_problem(abs(velocities["X"]) / table, self.gear, self.hob, "radial infeed"))

    def _end_cut(self) -> None:
        if self.cut is None:
            return
        cut, self.cut = self.cut, None
        for unit in self.units:
            before = cut.reach_before.get(id(unit))
            if before is not None and any(now < then for now, then in zip(unit.reach, before)):
                self.last_cut_of[id(unit)] = cut
                self.report.cuts.append(summary(cut, unit, self.body.half_length))
                self._check_run_out(cut, self.report.cuts[-1])

    def _check_run_out(self, cut: Cut, done) -> None:
        """An axial pass carries the generating zone past the face it leaves (§B8); a tangential
        worm-wheel pass carries the hob's trailing end past the centre plane."""
        least = 0.0 if self.worm_wheel else least_run_out(self.gear, self.swivel)
        problem = run_out_problem(done.run_out, least, done.unit)
        if problem:
            self.report.add(cut.number, cut.line, problem)

    # ---------------------------------------------------------------- the end

    def finish(self, lines: list[str]) -> None:
        self._end_cut()
        last = (len(lines), lines[-1] if lines else "")
        for unit in self.units:
            self._check_depth(unit, last)
        if self.report.header_time is not None:
            problem = header_problem(self.report.header_time, self.report.cycle_time)
            if problem:
                self.report.add(self.header_step.number, self.header_step.line, problem)
        else:
            self.report.add(*last, "no `; CYCLE TIME <m> MIN` header line: a hobbing program states its cycle "
                                   f"time (the simulation takes {self.report.cycle_time:.2f} min)")

    def _check_depth(self, unit: Solid, last: tuple[int, str]) -> None:
        cut = self.last_cut_of.get(id(unit))
        if cut is None:
            self.report.add(*last, f"{unit.name} is never cut")
            return
        stock = unit.stock()
        worst = max(range(len(stock)), key=stock.__getitem__)      # the first of equal heights, low to high
        z = unit.heights[worst] * self.senses.z
        if stock[worst] == math.inf:
            self.report.add(cut.number, cut.line, f"the cuts of {unit.name} never reach Z{z:.3f}: part of its face "
                                                  "is not cut")
        else:
            for at in (worst, min(range(len(stock)), key=stock.__getitem__)):
                problem = depth_problem(stock[at], self.allowance)
                if problem:
                    z = unit.heights[at] * self.senses.z
                    self.report.add(cut.number, cut.line, f"the last cut of {unit.name} {problem} at Z{z:.3f}")
                    return


TAKERS = {"header": BlockSimulation._header, "comment": BlockSimulation._comment,
          "block": BlockSimulation._block, "statement": BlockSimulation._statement, "shift": BlockSimulation._shift}


def _rapid_along_z(motion: int, start: dict, end: dict) -> bool:
    """A G0 that moves Z runs the hob along the teeth at rapid rate, with C trailing the Z
    differential: not a retract out of the hob's own gaps, so the gaps it cut are not free to it
    (the rapid between two cuts of a taper, inside the large end of its tip cone, ran through them)."""
    return motion == 0 and start.get("Z", end.get("Z")) != end.get("Z")


def _along_flipped_axis(position: dict) -> dict:
    """The position with the hob's shift along the cylinder's axis as the reduced swivel points it:
    Y rides on the swivel head (reference §A6: centre (X, Y·cos A, Z + Y·sin A)), so at A and at
    A − 180° the same shift lies on opposite sides of the pivot."""
    return {**position, "Y": -position["Y"]} if "Y" in position else position
