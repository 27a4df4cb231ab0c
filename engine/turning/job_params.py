"""A read drawing → the parameters of its turning job (design notes §8): every number taken
from the drawing is a named parameter in job.params or job.module_params, so it can be
edited in SQL and the job instantiated again. What the drawing does not say is assumed
from the defaults (engine.turning.defaults) and said in `notes`."""
from __future__ import annotations

import math
from typing import Any

import msgspec

from ..drawings.drawing import Drawing, Operation
from ..drawings.profile import merged_bounds
from ..errors import EngineError
from ..machines.turning_cutting import DEFAULT_TOOL_MATERIAL, DEFAULT_WORKPIECE_MATERIAL, job_materials
from .defaults import (
    CLEARANCE,
    DEFAULT_FEED,
    DEFAULT_INFEED_ANGLE,
    DEFAULT_SPEED,
    DEFAULT_THREAD_DEPTH_PER_PASS,
    PROFILE_DEFAULTS,
    STOCK_MARGIN,
    TOOL_CHANGE_DISTANCE,
)
from .model import key
from .names import MAX_OPERATIONS, SLOT_DEFAULTS
from .program_names import drawing_names
from .segments import path_param


class ProfileOptions(msgspec.Struct, frozen=True):
    """Cutting data for a drawing with a profile only (rough, then finish along the profile);
    None = not given, the default below applies."""
    rough_depth: float | None = None      # mm radial per rough pass
    allowance: float | None = None        # mm left on the profile by the rough passes
    tool: int | None = None
    speed: float | None = None            # r/min
    feed: float | None = None             # mm/min
    stock_diameter: float | None = None   # mm; default the profile's largest diameter + STOCK_MARGIN

    def given(self) -> bool:
        return any(value is not None for value in msgspec.structs.astuple(self))

    def cutting_data_given(self) -> bool:
        return any(getattr(self, name) is not None for name in PROFILE_DEFAULTS)

    def value(self, name: str):
        given = getattr(self, name)
        return PROFILE_DEFAULTS[name] if given is None else given


class TurningJob(msgspec.Struct):
    params: dict
    module_params: dict
    operations: list[dict] = []   # a summary per operation, for the report
    notes: list[str] = []


def turning_job(drawing: Drawing, machine: str, gear_class: str, program_number: int,
                options: ProfileOptions = ProfileOptions(), alternate: list[int] | None = None,
                program_name: str | None = None, materials: tuple[str | None, str | None] = (None, None)
                ) -> TurningJob:
    """`materials`: (tool material of every operation, workpiece material), None = the default
    (engine.machines.turning_cutting; reference §E1)."""
    job = TurningJob({}, {})
    if drawing.scale_to_mm != 1.0:
        job.notes.append(f"{drawing.units} drawing: lengths scaled ×{drawing.scale_to_mm:g} to mm; the @-codes "
                         "are taken as written, @F in mm/min, @P and @D in mm, @S in r/min (not scaled)")
    if drawing.operations:
        if options.cutting_data_given():
            raise EngineError(f"{drawing.source.name} has operation layers ({_layers(drawing)}); --rough-depth, "
                              "--allowance, --tool, --speed and --feed are for profile-only drawings: leave "
                              "them out (each layer's @-codes apply)")
        for op in drawing.operations:
            add_drawn_operation(job, op)
        stock_diameter = options.stock_diameter
    elif not options.given():
        raise EngineError(f"{drawing.source.name} has a profile but no operation layers 1, 2, …; give "
                          "--rough-depth MM (or any of --allowance, --tool, --speed, --feed, --stock-diameter) "
                          "to rough and finish it along the profile, or draw the tool paths on layers 1 … n")
    else:
        add_profile_operations(job, options)
        stock_diameter = blank_diameter(drawing, options)
    drawing_name, name, naming_notes = drawing_names(drawing.source.name, program_name, gear_class, program_number)
    job.notes.extend(naming_notes)
    job.params = job_params(drawing, (drawing_name, name), machine, gear_class, program_number, stock_diameter,
                            alternate, job.notes)
    add_materials(job, *materials)
    return job


def add_materials(job: TurningJob, tool_material: str | None, workpiece_material: str | None) -> None:
    """params.workpiece_material and each prep:n.tool_material, stored so SQL can change them (the
    cutting-data windows of reference §E1 depend on them); unknown names refused here, at import."""
    job.params["workpiece_material"] = workpiece_material or DEFAULT_WORKPIECE_MATERIAL
    for name, values in job.module_params.items():
        if name.startswith("prep:"):
            values["tool_material"] = tool_material or DEFAULT_TOOL_MATERIAL
    for name in job.module_params:
        if name.startswith("prep:"):
            job_materials(job.params, job.module_params, int(name.partition(":")[2]))


def _layers(drawing: Drawing) -> str:
    return ", ".join(op.layer for op in drawing.operations)


def job_params(drawing: Drawing, names: tuple[str, str], machine: str, gear_class: str, program_number: int,
               stock_diameter: float | None, alternate, notes: list[str]) -> dict:
    z_min, z_max, _, _ = drawing.profile.bounds
    tool_change_z, tool_change_x = tool_change(drawing, stock_diameter, notes)
    return {
        **SLOT_DEFAULTS,
        "program_name": names[1], "program_number": program_number, "drawing": names[0], "units": drawing.units,
        "machine": machine, "gear_class": gear_class,
        "profile": path_param(drawing.profile.segments), "closed_by_axis": drawing.profile.closed_by_axis,
        "stock_diameter": stock_diameter, "stock_z_front": round(z_max, 6), "stock_z_back": round(z_min, 6),
        "tool_change_z": tool_change_z, "tool_change_x": tool_change_x, "clearance": CLEARANCE,
        "alternate": list(alternate) if alternate else None,
    }


def tool_change(drawing: Drawing, stock_diameter: float | None, notes: list[str]) -> tuple[float, float]:
    """(Z, X diameter) of the tool-change position: the drawing's POINT, else beyond everything."""
    if drawing.tool_change is not None:
        return round(drawing.tool_change.z, 6), round(drawing.tool_change.x_diameter, 6)
    segments = drawing.profile.segments + [s for op in drawing.operations for s in op.segments]
    _, z_max, _, r_max = merged_bounds(segments)
    radius = max(r_max, (stock_diameter or 0.0) / 2.0)
    point = (round(z_max + TOOL_CHANGE_DISTANCE, 3), round(2.0 * (radius + TOOL_CHANGE_DISTANCE), 3))
    notes.append(f"no tool-change POINT on layer 0: tool change at Z{point[0]:g} X{point[1]:g} "
                 f"({TOOL_CHANGE_DISTANCE:g} mm beyond the drawing; params.tool_change_z/_x)")
    return point


def blank_diameter(drawing: Drawing, options: ProfileOptions) -> float:
    largest = 2.0 * drawing.profile.bounds[3]
    if options.stock_diameter is None:
        return float(math.ceil(round(largest + STOCK_MARGIN, 6)))   # 14.000000000000007 is 14
    if options.stock_diameter < largest:
        raise EngineError(f"--stock-diameter {options.stock_diameter:g} is smaller than the profile's largest "
                          f"diameter {largest:.3f} mm; give a larger blank")
    return options.stock_diameter


def add_drawn_operation(job: TurningJob, op: Operation) -> None:
    n = op.number
    if n > MAX_OPERATIONS:
        raise EngineError(f"layer {op.layer!r}: operation {n} is beyond the turning templates' "
                          f"{MAX_OPERATIONS} operation slots; renumber the layers 1 … {MAX_OPERATIONS}")
    codes: dict[str, Any] = op.codes   # each @-code's value has its own type
    tool = codes.get("tool") or _assumed(job, op, "@T", "tool", n, " (the operation number, by convention)")
    speed = codes.get("spindle_rpm") or _assumed(job, op, "@S", "spindle_rpm", DEFAULT_SPEED)
    cutmotion = {"kind": op.kind, "paths": [path_param(path) for path in op.paths], "op_present": True}
    if op.kind == "THREAD":
        depth = codes.get("depth_per_pass") or _assumed(job, op, "@D", "depth_per_pass",
                                                        DEFAULT_THREAD_DEPTH_PER_PASS)
        cutmotion.update(thread_pitch=codes["thread_pitch"], depth_per_pass=depth,
                         infeed_angle=codes.get("infeed_angle", DEFAULT_INFEED_ANGLE))
    else:
        cutmotion["feed"] = codes.get("feed") or _assumed(job, op, "@F", "feed", DEFAULT_FEED)
    add_operation(job, n, tool, speed, bool(codes.get("coolant", False)), cutmotion, f"layer {op.layer}")


def _assumed(job: TurningJob, op: Operation, code: str, name: str, value, why: str = ""):
    job.notes.append(f"layer {op.layer!r} (operation {op.number}, {op.kind}) has no {code}: "
                     f"{name} {value:g} assumed{why}")
    return value


def add_profile_operations(job: TurningJob, options: ProfileOptions) -> None:
    feed, tool, speed = options.value("feed"), options.value("tool"), options.value("speed")
    rough = {"kind": "ROUGH", "paths": [], "feed": feed, "depth_per_pass": options.value("rough_depth"),
             "allowance": options.value("allowance"), "op_present": True}
    finish = {"kind": "FINISH", "paths": [], "feed": feed, "op_present": True}
    add_operation(job, 1, tool, speed, False, rough, "profile (rough down to the allowance)")
    add_operation(job, 2, tool, speed, False, finish, "profile (finish)")


def add_operation(job: TurningJob, n: int, tool: int, speed: float, coolant: bool, cutmotion: dict,
                  source: str) -> None:
    job.module_params[key("prep", n)] = {"tool": tool, "tool_offset": tool, "op_present": True}
    job.module_params[key("cutcond", n)] = {"spindle_rpm": speed, "coolant": coolant, "op_present": True}
    job.module_params[key("cutmotion", n)] = cutmotion
    job.operations.append({"operation": n, "kind": cutmotion["kind"], "source": source, "tool": tool,
                           "spindle_rpm": speed, "feed": cutmotion.get("feed"), "coolant": coolant,
                           "paths": len(cutmotion["paths"])})
