"""The passes of each operation of a turning job, computed from its stored parameters at every
instantiation (so a feed, a depth or a segment edited in SQL gives the new program).

Operation kinds (@G): ROUGH with drawn paths is fed along each drawn path; ROUGH without
paths roughs the blank down to the profile plus the allowance in horizontal passes (seed
001); FINISH follows its drawn paths, or the profile when it has none (of a closed section
its outer side); SLOT plunges along
each drawn path and retracts; THREAD cuts the drawn thread in passes of @D at the @A
infeed angle. FACE is fed along its drawn paths like ROUGH, PART plunges like SLOT: on
the drawn tool-centre path the motion is the same.
"""
from __future__ import annotations

from functools import cached_property

import msgspec

from ..drawings.geometry import Line, Segment
from ..drawings.profile import END_MATCH_TOLERANCE_MM, Profile, merged_bounds
from ..errors import EngineError
from . import toolpaths
from .gouge import PartIndex, check_no_gouge
from .moves import Pass
from .region import Surroundings, flattened_outline
from .segments import path_from_param

DRAWN_FEED_KINDS = ("ROUGH", "FACE")
PLUNGE_KINDS = ("SLOT", "PART")
KINDS = ("ROUGH", "SLOT", "FINISH", "THREAD", "FACE", "PART")


class JobGeometry(msgspec.Struct, frozen=True, dict=True):   # dict: room for the cached properties
    """What every operation of a job shares: the profile, the closed outline, the blank."""
    profile: list[Segment]
    finish_path: list[Segment]     # the side of the profile a finishing tool follows
    outline: list[Segment]
    stock: tuple[float, float, float] | None    # (z_front, z_back, radius) of the blank
    clearance: float
    tool_change_radius: float

    @cached_property
    def edges(self) -> tuple:
        return tuple(flattened_outline(self.outline))

    @cached_property
    def surroundings(self) -> Surroundings:
        return Surroundings(self.edges, self.stock, self.clearance)

    @cached_property
    def part_index(self) -> PartIndex:
        return PartIndex(self.edges)


def job_geometry(params: dict) -> JobGeometry:
    """The geometry of a job whose parameters model.check_job_params has checked."""
    profile = path_from_param(params.get("profile"), "params.profile")
    if not profile:
        raise EngineError("params.profile is empty; a turning job needs the part's profile segments")
    closed_by_axis = bool(params.get("closed_by_axis"))
    closing = Profile(profile, closed_by_axis, merged_bounds(profile)).closing_segments()
    stock = None
    if params.get("stock_diameter") is not None:
        stock = (float(params["stock_z_front"]), float(params["stock_z_back"]), params["stock_diameter"] / 2.0)
    finish_path = off_the_axis(profile) if closed_by_axis else outer_side(profile)
    clearance, tool_change_radius = float(params["clearance"]), params["tool_change_x"] / 2.0
    return JobGeometry(profile, finish_path, [*profile, *closing], stock, clearance, tool_change_radius)


def off_the_axis(profile: list[Segment]) -> list[Segment]:
    """The profile without the faces at its ends that reach the axis: a turning tool coming
    from the outside finishes the outside and leaves from it; those faces are FACE or PART work."""
    kept = list(profile)
    while kept and is_face_to_axis(kept[0]):
        kept.pop(0)
    while kept and is_face_to_axis(kept[-1]):
        kept.pop()
    return kept or profile


def is_face_to_axis(segment: Segment) -> bool:
    (z0, r0), (z1, r1) = segment.start, segment.end
    return (isinstance(segment, Line) and abs(z0 - z1) <= END_MATCH_TOLERANCE_MM
            and min(r0, r1) <= END_MATCH_TOLERANCE_MM)


def outer_side(closed: list[Segment]) -> list[Segment]:
    """The outer side of a closed section, as a half-profile would be drawn: from its start
    (largest Z, then largest radius; the reader orients it counter-clockwise, so it runs
    towards −Z along the top) to where it first reaches its smallest Z. The faces and the
    bore or axis side are not part of it, as the axis closes a half-profile."""
    z_min = merged_bounds(closed)[0]
    for count, segment in enumerate(closed, start=1):
        if segment.end[0] <= z_min + END_MATCH_TOLERANCE_MM:
            return closed[:count]
    return closed


def operation_passes(geometry: JobGeometry, cutmotion: dict, where: str) -> list[Pass]:
    """The passes of one operation (`where` names its module parameters in errors), each
    entered and left at a travel radius clear of part and blank; the operation is entered
    from the tool-change point by Z first and left by X up to it first."""
    passes = toolpaths.standalone(_passes(geometry, cutmotion, where), geometry.surroundings)
    passes = from_and_to_tool_change(passes, geometry.tool_change_radius)
    if cutmotion.get("kind") != "THREAD":   # a thread cuts below the drawn profile by design
        check_no_gouge(passes, geometry.part_index, where)
    return passes


def from_and_to_tool_change(passes: list[Pass], tool_change_radius: float) -> list[Pass]:
    """The template's tool-change block moves Z only: the operation starts with a Z move at
    the tool-change X and ends lifted to it."""
    if not passes:
        return passes
    first, last = passes[0][0], passes[-1][-1]
    lift_in, lift_out = (max(tool_change_radius, move.x / 2.0) for move in (first, last))
    passes = [list(one) for one in passes]
    passes[0].insert(0, toolpaths.rapid(first.z, lift_in))
    passes[-1].append(toolpaths.rapid(last.z, lift_out))
    return passes


def _passes(geometry: JobGeometry, cutmotion: dict, where: str) -> list[Pass]:
    kind = cutmotion["kind"]
    paths = [path_from_param(path, f"{where}.paths[{i}]") for i, path in enumerate(cutmotion.get("paths") or [])]
    if not paths and kind in ("ROUGH", "FINISH"):
        return _along_profile(geometry, kind, cutmotion, where)
    if not paths:
        raise EngineError(f"{where}: a {kind} operation needs drawn paths (paths is empty)")
    clearance = geometry.clearance
    if kind in DRAWN_FEED_KINDS:
        return toolpaths.drawn_rough_passes(paths, clearance)
    if kind in PLUNGE_KINDS:
        return toolpaths.slot_passes(paths, clearance)
    if kind == "FINISH":
        return [one for path in paths for one in toolpaths.finish_passes(path, clearance)]
    return toolpaths.thread_passes(paths, cutmotion["depth_per_pass"], cutmotion["infeed_angle"],
                                   cutmotion["thread_pitch"], clearance, geometry.surroundings)


def _along_profile(geometry: JobGeometry, kind: str, cutmotion: dict, where: str) -> list[Pass]:
    if kind == "FINISH":
        return toolpaths.finish_passes(geometry.finish_path, geometry.clearance)
    if geometry.stock is None:
        raise EngineError(f"{where}: roughing along the profile needs the blank; set params.stock_diameter, "
                          "stock_z_front and stock_z_back")
    z_front, z_back, radius = geometry.stock
    return toolpaths.profile_rough_passes(geometry.outline, radius, cutmotion["depth_per_pass"],
                                          cutmotion["allowance"], z_front, z_back, geometry.clearance)
