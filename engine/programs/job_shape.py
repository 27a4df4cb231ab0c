"""The shape of a stored job's parameters, checked where they enter the engine (issue 26).

A runner may INSERT a job in SQL with module parameters the engine never stores (`{"cutmotion:1":
"x"}`, a cut of null, a feed of "a"). Everything that reads a hobbing job's cuts (its cycle time,
engine.hobbing.machine_job.with_cycle_time; making it again; rendering a stored program again) first
holds the job to the shape the planner writes: params and module_params JSON objects, each module
named `kind:n` (n a whole number) with an object of values, each cut's `cut_on` true or false and
its positions and feeds (mm, mm/min) numbers. A job of another shape is refused in one line naming
the job and the parameter (exit 1), never a crash."""
from __future__ import annotations

import math

from ..errors import EngineError
from ..hobbing.choices import WORM_FEEDS
from ..hobbing.machine_job import with_cycle_time
from ..machines.records import Machine

# A cut's values that are positions (mm) and feeds (mm/min), read as numbers by the cycle time.
NUMBER_PREFIXES = ("feed_", "crown_x_", "taper_x_", "face_", "z_", "x_", "cut_x")


def check_job_shape(job_id: int, params, module_params) -> None:
    """EngineError (one line) unless the job's parameters are the shape the engine stores."""
    if not isinstance(params, dict) or not isinstance(module_params, dict):
        which = "params" if not isinstance(params, dict) else "module_params"
        raise EngineError(f"job {job_id}: {which} is not a JSON object; {_REMEDY}")
    for key, values in module_params.items():
        kind, _, number = key.partition(":")
        if not kind or not number.isdecimal():
            raise EngineError(f"job {job_id}: module_params key {key!r} is not named kind:n; {_REMEDY}")
        if not isinstance(values, dict):
            raise EngineError(f"job {job_id}: module_params.{key} is {_shown(values)}, not an object of values; "
                              f"{_REMEDY}")
        if kind == "cutmotion":
            _check_cut(job_id, key, values)


def job_with_cycle_time(job_id: int, params: dict, module_params: dict, shape: str, machine: Machine) -> dict:
    """The job's params with the cycle time of its cuts (engine.hobbing.machine_job), its shape
    checked first; a value the cut's shape needs and the job lacks is named, not a crash."""
    check_job_shape(job_id, params, module_params)
    try:
        return with_cycle_time(params, module_params, shape, machine)
    except KeyError as missing:
        raise EngineError(f"job {job_id}: its params or a cut of its module_params has no {missing} "
                          f"(a {shape} cut needs it); {_REMEDY}") from None
    except (TypeError, ValueError) as error:
        raise EngineError(f"job {job_id}: its params are not numbers where its {shape} cuts need them "
                          f"({error}); {_REMEDY}") from None


def job_with_worm_feed(params: dict, model) -> dict:
    """A worm wheel's job stored before its header named its worm feed (it said `climb` over a
    radial plunge, issue 29) made again with the feed word its cuts are: radial or tangential."""
    if getattr(model, "axial_passes", True) or params.get("feed_mode") in WORM_FEEDS:
        return params
    return {**params, "feed_mode": "tangential" if params.get("tangential") is True else "radial"}


def _check_cut(job_id: int, key: str, cut: dict) -> None:
    if not isinstance(cut.get("cut_on"), bool):
        raise EngineError(f"job {job_id}: module_params.{key}.cut_on is {_shown(cut.get('cut_on'))}, "
                          f"not true or false; {_REMEDY}")
    for name, value in cut.items():
        if name.startswith(NUMBER_PREFIXES) and not _is_number(value):
            raise EngineError(f"job {job_id}: module_params.{key}.{name} is {_shown(value)}, not a number; "
                              f"{_REMEDY}")


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _shown(value) -> str:
    text = repr(value) if value is not None else "null"
    return text if len(text) <= 40 else text[:37] + "..."


_REMEDY = "not the shape the engine stores; make a new job with `engine instantiate --gear ID`"
