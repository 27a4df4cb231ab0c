"""A stored hobbing job checked again before it is made again (`engine instantiate --job/--jobs`,
issue 26): a runner may INSERT or UPDATE a job in SQL, so its hob and parameters are held to the
tests a new job passes, never taken as they are.

* The hob: one `engine hobs match` accepts for the gear (engine.gears.hob_matching.unmet_need, the
  planner's own acceptance), so a copy of gear 42's job (m 2) naming a m 2.5 hob is refused.
* The facts of the records: the gear's module, teeth, angles and diameters, the hob's starts, tip
  diameter and hand, and what follows from them (swivel, lead angle, coupling, differential) are
  re-derived by the class's model from the gear, hob and machine records as they are now, and the
  stored values must equal them: they describe the workpiece and the tool, they are not choices.
* What a shop may edit in job.params (docs/guide/instantiate-and-batches.md: the hob speed, the
  feeds, the choices of a new job, the program name) must pass the bounds a new job's value passes:
  the choices' own checks (engine.hobbing.choices.Choices), the machine's module, hob spindle and
  table speed limits, and the feed maxima of reference §C (CuttingData.with_overrides).
Every refusal is one line naming the job and the parameter; nothing is stored.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..errors import EngineError
from ..gears.cutting_data import default_cutting_data, per_minute
from ..gears.hob_matching import unmet_need
from ..gears.process_notes import CUT_KIND_BY_NAME
from ..gears.speed_table import speeds_of
from ..hobbing.choices import WORM_FEEDS, Choices
from .instantiate import check_machine_fits, check_speeds  # the planner's own checks

if TYPE_CHECKING:
    from ..gears.records import Gear, Hob
    from ..machines.records import Machine

# Job parameters that state the gear, the hob and the machine, and what follows from them alone
# (engine.hobbing.cylindrical base_params): equal to the records, whatever the job's choices.
RECORD_PARAMETERS = ("gear_id", "gear_class", "machine", "hob_id", "mn", "z2", "alpha_n", "beta", "hand", "b",
                     "da2", "df2", "z0", "da0", "hob_hand", "swivel", "lead_angle", "coupling_b", "differential",
                     "tool_number")
# A duplex gear's further unit (engine.hobbing.duplex, module sync:n): its number, teeth and width.
UNIT_PARAMETERS = ("unit", "z2", "b")
RELATIVE_TOLERANCE = 1e-9   # JSON numbers read back as they were stored; only float noise allowed
NOTHING_STORED = "nothing stored"


def check_hobbing_job(job_id: int, gear_class: str, model, gear: Gear, hob: Hob, machine: Machine,
                      params: dict, module_params: dict) -> None:
    """Refuse the stored job (EngineError, one line) unless its hob fits the gear, its record
    parameters equal the records and its hob speed is within a new job's bounds."""
    choices = job_choices(job_id, params)
    _check_hob(job_id, gear, hob, model.hob_purpose, model.shift_travel(choices))
    _check_records(job_id, gear_class, model, gear, hob, machine, params, module_params, choices)
    n0 = _number(job_id, params, "n0", "params.n0")
    _refused_as_new(job_id, "params.n0", lambda: _cutting_table(gear, hob, machine).with_overrides(hob_speed=n0))
    _refused_as_new(job_id, "params.n0", lambda: check_speeds(gear, hob.starts, n0, machine))
    _refused_as_new(job_id, "params.mn", lambda: check_machine_fits(gear, machine))


def check_hobbing_feeds(job_id: int, gear: Gear, hob: Hob, machine: Machine, params: dict, module_params: dict,
                        bounded: bool = True) -> None:
    """Every cut's feeds of the stored job numbers above 0 (a feed of 0 never ends the pass) and,
    `bounded`, within a new job's maxima (reference §C). The maxima are checked after the
    simulation has read the program, so a feed beyond the roughing maximum gets its line named."""
    n0 = _number(job_id, params, "n0", "params.n0")
    table = _cutting_table(gear, hob, machine)
    for key, cut in sorted(module_params.items()):
        if key.startswith("cutmotion:") and isinstance(cut, dict) and cut.get("cut_on") is not False:
            teeth = _unit_teeth(job_id, module_params, key, gear.teeth)
            _check_cut(job_id, key, cut, table if bounded else None, teeth, gear, hob, n0)


def _unit_teeth(job_id: int, module_params: dict, key: str, teeth: int) -> float:
    """The teeth of the unit the cut `cutmotion:n` cuts: a duplex gear's further unit starts at
    its `sync:m` (m ≤ n, the last one), which couples the table to its own tooth count."""
    number = int(key.partition(":")[2]) if key.partition(":")[2].isdecimal() else 0
    syncs = sorted((int(name.partition(":")[2]), name) for name in module_params
                   if name.startswith("sync:") and name.partition(":")[2].isdecimal())
    unit = [name for m, name in syncs if m <= number]
    if not unit or not isinstance(module_params[unit[-1]], dict):
        return teeth
    return _number(job_id, module_params[unit[-1]], "z2", f"module_params.{unit[-1]}.z2")


def _axial_mode(params: dict):
    """The job's feed mode for its axial passes: a worm wheel's job states its worm feed there
    (radial or tangential, the header's word) and has none."""
    mode = params.get("feed_mode", "climb")
    return None if mode in WORM_FEEDS else mode


def job_choices(job_id: int, params: dict) -> Choices:
    """The choices the stored job was made with, as a new job's are checked (allowance, feed mode,
    shift, and its cut count: a new job's search may have taken two cuts where the module says one)."""
    worm_feed = "tangential" if params.get("tangential") is True else "radial"
    cuts = params.get("cuts") if params.get("cuts") in (1, 2) else None
    return _refused_as_new(job_id, "params", lambda: Choices(
        cuts=cuts, coolant=bool(params.get("coolant", True)), feed_mode=_axial_mode(params),
        shift_y=_number(job_id, params, "shift_y", "params.shift_y", 0.0),
        shift_per_part=_number(job_id, params, "shift_per_part", "params.shift_per_part", 0.0),
        tailstock=bool(params.get("tailstock", True)), worm_feed=worm_feed,
        allowance=_number(job_id, params, "allowance", "params.allowance", 0.0)))


def _check_hob(job_id: int, gear: Gear, hob: Hob, purpose: str, shift_travel: float) -> None:
    unmet = unmet_need(gear, hob, purpose=purpose, shift_travel=shift_travel)
    if unmet is not None:
        raise EngineError(f"job {job_id}: hob {hob.id} does not fit gear {gear.id}: the gear needs {unmet}; "
                          f"name a hob `engine hobs match --gear {gear.id}` accepts (job.hob_id), or make a new "
                          f"job with `engine instantiate --gear {gear.id}`; {NOTHING_STORED}")


def _check_records(job_id: int, gear_class: str, model, gear: Gear, hob: Hob, machine: Machine, params: dict,
                   module_params: dict, choices: Choices) -> None:
    """The record parameters re-derived by the class's model from the records, as the planner
    derives a new job's (the cutting data and cut count do not enter them). One the job lacks is
    left to the template, which names an unknown parameter it reads."""
    derived = _refused_as_new(job_id, f"gear {gear.id} with hob {hob.id}", lambda: model.job(
        gear, gear_class, hob, machine, _cutting_table(gear, hob, machine), choices))
    stated: list[tuple[str, object, str, object]] = [
        (f"params.{name}", params, name, derived.params[name]) for name in RECORD_PARAMETERS if name in derived.params]
    stated += [(f"module_params.{key}.{name}", module_params.get(key), name, unit[name])   # duplex units
               for key, unit in derived.module_params.items() if key.startswith("sync:")
               for name in UNIT_PARAMETERS if name in unit]
    for where, values, name, value in stated:
        if isinstance(values, dict) and name in values and not _same(values[name], value):
            raise EngineError(f"job {job_id}: {where} = {values[name]!r} is not {value!r}, the value of the "
                              f"records (gear {gear.id}, hob {hob.id}, machine {machine.name}); correct the job "
                              f"or make a new job with `engine instantiate --gear {gear.id}`; {NOTHING_STORED}")


def _cutting_table(gear: Gear, hob: Hob, machine: Machine):
    """The §C defaults for the gear and hob: the bounds of CuttingData.with_overrides (its values
    are not compared with the job's)."""
    return default_cutting_data(gear.module, gear.material, bool(hob.coating), hob.tip_diameter, machine.spindle_max,
                                speeds_of(gear))


def _same(stored, derived) -> bool:
    numbers = (int, float)
    if isinstance(derived, numbers) and not isinstance(derived, bool):
        return (isinstance(stored, numbers) and not isinstance(stored, bool)
                and math.isclose(stored, derived, rel_tol=RELATIVE_TOLERANCE, abs_tol=RELATIVE_TOLERANCE))
    return stored == derived


def _check_cut(job_id: int, key: str, cut: dict, table, teeth: float, gear: Gear, hob: Hob, n0: float) -> None:
    """Each feed of the cut above 0 and, with the §C `table`, the axial one per workpiece
    revolution (of the unit's `teeth`) within the maximum for its kind (rough or finish), the
    gear and the hob (the §C table and the chip bound of §C1)."""
    one_mm_per_rev = per_minute(1.0, n0, hob.starts, int(teeth))   # mm/min per mm/rev (§B5)
    for name in ("feed_axial", "feed_radial", "feed_tangential"):
        if name in cut:
            where = f"module_params.{key}.{name}"
            value = _number(job_id, cut, name, where)
            if not value > 0:
                raise EngineError(f"job {job_id}, {where}: {value:g} mm/min must be above 0; correct "
                                  f"job.{_column(where)}; "
                                  f"{NOTHING_STORED}")
            kind = CUT_KIND_BY_NAME.get(str(cut.get("cut_name")), "rough")
            along = name in ("feed_axial", "feed_tangential")   # a tangential pass runs at its kind's axial feed
            override = {f"axial_feed_{kind}" if along else "radial_feed": value / one_mm_per_rev}
            if table is not None:
                _refused_as_new(job_id, f"{where} = {value:g} mm/min",
                                lambda override=override: table.with_overrides(gear, hob, **override))


def _number(job_id: int, values: dict, name: str, where: str, default: float | None = None) -> float:
    value = values.get(name, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise EngineError(f"job {job_id}: {where} = {value!r} must be a number; correct job.{_column(where)}; "
                          f"{NOTHING_STORED}")
    return float(value)


def _column(where: str) -> str:
    """The job's column a parameter lives in: `module_params.cutmotion:2.feed_axial` → module_params."""
    return where.split(".", 1)[0]


def _refused_as_new(job_id: int, where: str, check):
    """check(), its refusal (a new job's words) said of the job's parameter."""
    try:
        return check()
    except EngineError as error:
        message = str(error).rstrip().removesuffix(NOTHING_STORED).rstrip("; ")
        raise EngineError(f"job {job_id}, {where}: {message}; {NOTHING_STORED}") from None
