"""A job's parameters made ready for its machine: the signed values in the machine's senses
(engine.hobbing.conventions), the machine's setup (work offset, tool call, door and load
blocks, spindle orientation), the dialect the template renders the coupling in
(engine.hobbing.dialects), the working area widened to the load position, and the cycle
time of the program the template will write (engine.hobbing.cycle_time) and its floor-to-floor
time (engine.hobbing.floor_time)."""
from __future__ import annotations

from ..gears.records import Hob
from ..machines.records import Machine
from . import conventions
from .cycle_time import cycle_time
from .dialects import dialect_parameters
from .floor_time import floor_to_floor
from .passes import LIMIT_MARGIN

SETUP_PARAMETERS = frozenset({"work_offset", "tool_number", "door_close_m", "door_open_m", "load_position",
                              "load_x", "load_z", "orient_before_coupling", "cycle_time", "floor_to_floor",
                              "dialect", "fanuc", "program_number", "egb_helix_sign",
                              "egb_start", "egb_teeth", "egb_stop"})


def machine_setup(machine: Machine, hob: Hob) -> dict:
    """What the machine record says every program does; a door M of 0 and load_position False
    mean the machine has none (the template rows are switched off)."""
    has_load = machine.load_x is not None and machine.load_z is not None
    return {"work_offset": machine.work_offset, "tool_number": hob.tool_number,
            "door_close_m": machine.door_close_m or 0, "door_open_m": machine.door_open_m or 0,
            "load_position": has_load,
            "load_x": float(machine.load_x) if machine.load_x is not None and has_load else 0.0,
            "load_z": float(machine.load_z) if machine.load_z is not None and has_load else 0.0,
            "orient_before_coupling": bool(machine.orient_before_coupling)}


def machine_job(params: dict, module_params: dict, machine: Machine, hob: Hob, shape: str) -> tuple[dict, dict]:
    """(job parameters, module parameters) in program values, with the setup and cycle time.
    `shape` names the cut of engine.hobbing.cycle_time.PASSES the class's template emits."""
    job = {**conventions.on_machine(params, machine), **machine_setup(machine, hob)}
    modules = {key: conventions.on_machine(values, machine) for key, values in module_params.items()}
    if job["load_position"]:
        _widen(job, "x", job["load_x"])
        _widen(job, "z", job["load_z"])
    return with_cycle_time(job, modules, shape, machine), modules


def with_cycle_time(job: dict, modules: dict, shape: str, machine: Machine) -> dict:
    """The job with the cycle and floor-to-floor times of its program (program values in, as stored): a stored job
    whose feeds were edited is made again with the time its program now takes, so the header
    never tells the operator a time the simulation does not find. The dialect's parameters come
    from the record here too (engine.hobbing.dialects), so a job stored before they existed is
    made again in its machine's dialect."""
    gear_id = job.get("gear_id")
    job = {**job, **dialect_parameters(machine, gear_id if type(gear_id) is int else 0)}
    cuts = [modules[key] for key in sorted(modules, key=_module_order)
            if key.startswith("cutmotion:") and modules[key]["cut_on"]]
    minutes = cycle_time(job, cuts, shape, machine.rapid_rate)
    return {**job, "cycle_time": round(minutes, 4),   # printed to 0.1 once
            "floor_to_floor": round(floor_to_floor(job, modules, machine, minutes), 4)}


def _module_order(key: str) -> tuple:
    kind, _, number = key.partition(":")
    return kind, int(number)


def _widen(job: dict, axis: str, value: float) -> None:
    job[f"{axis}_lower"] = round(min(job[f"{axis}_lower"], value - LIMIT_MARGIN), 3)
    job[f"{axis}_upper"] = round(max(job[f"{axis}_upper"], value + LIMIT_MARGIN), 3)
