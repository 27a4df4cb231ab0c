"""Floor-to-floor time of a hobbing program, the header line `; FLOOR TO FLOOR <min> MIN` (issue 29):
what a planner books for one part, the cycle time (engine.hobbing.cycle_time) plus what the program
does besides moving, at the times its machine record states (migration 0034; reference §B16).

The definition the simulation holds the header to, from the program text and the machine record
(engine.simulation.hobbing.floor_facts): seconds of
* the swivel: |ΔA| summed over the program's A words, from the head's 0°, over swivel_speed (°/s);
* a spindle run-up for each M3 or M4, a synchronisation for each EGON;
* the tailstock for each M20 and each M21, the door for each of its close and open M codes;
* a tool call for each T word; and loading and unloading the part once;
added to the cycle time in minutes. A machine that does not state all of them gets no such
line (0.0 here: the templates emit the line where it is above 0)."""
from __future__ import annotations

from ..machines.records import FLOOR_TIMES, Machine, unstated_floor_times
from ..notes import Note


def floor_to_floor(job: dict, modules: dict, machine: Machine, cycle: float) -> float:
    """Minutes from one part's loading to the next's (program values in, as the template reads
    them: its one swivel A, one tool call, a coupling and a spindle start per unit (a cluster gear's
    next unit stops the spindle, couples, starts it again), the tailstock
    clamped and released when the job clamps it, the door's blocks where the machine has them)."""
    if unstated_floor_times(machine):
        return 0.0
    swivel, runup, sync, tailstock, door, tool, load = (float(getattr(machine, name)) for name in FLOOR_TIMES)
    couplings = 1 + sum(1 for key, values in modules.items() if key.startswith("sync:") and "unit" in values)
    doors = (job["door_close_m"] > 0) + (job["door_open_m"] > 0)
    seconds = (abs(job["swivel"]) / swivel + couplings * (runup + sync) + 2 * job["tailstock"] * tailstock
               + doors * door + tool + load)
    return cycle + seconds / 60


def floor_time_notes(machine: Machine) -> list[str]:
    """Why a program for a machine that states some of its times but not all has no floor-to-floor
    line (new-user review 29: nothing said so); nothing where it states all or none."""
    missing = unstated_floor_times(machine)
    if not missing or len(missing) == len(FLOOR_TIMES):
        return []
    return [Note(f"no floor-to-floor time: machine {machine.name} does not state {', '.join(missing)}; "
                 "state them on its record (docs/guide/machines-and-simulation.md)", "no floor-to-floor time")]
