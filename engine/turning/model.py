"""The turning model: a job's stored parameters → the module parameters its template runs with.

The turning templates (seed_templates/classes/turning_iso.csv, turning_840d.csv) have one
slot per operation n = 1 … MAX_OPERATIONS: rows of modules prep:n (tool change), cutcond:n
(spindle, coolant) and cutmotion:n (feed, tool path), identical for every n, so the module
library stores each row body once. A slot reads its operation's parameters from its module
scope; the job parameters hold defaults (op_present false, …) so a slot whose operation is
absent evaluates and emits nothing. At every instantiation the passes are computed again
from the stored parameters and handed to the template as `moves`.
"""
from __future__ import annotations

from ..errors import EngineError
from ..names import NAME_RULES, is_safe, shown
from ..nc.words import MAX_TOOL
from . import toolpaths
from .arc_split import with_short_arcs
from .cutting_check import check_cutting_data
from .material import check_job_rapids
from .moves import Move, Pass
from .names import MAX_OPERATIONS
from .operations import KINDS, JobGeometry, job_geometry, operation_passes
from .params import FIX, bool_param, integer_param, number_param
from .reach import check_turnable_from_outside

# O0001 … O8999: O9000 … O9999 hold the machine builder's macros on Fanuc-type controls, so a
# program stored there would replace one (the verifier refuses such a number too).
ISO_PROGRAM_NUMBERS = 8999
MAX_INFEED_ANGLE = 60.0        # degrees: half a 60° thread's flank angle is 30; beyond 60 the tool rubs
# What each alternated operation must share with its partner: the passes of both run with A's rows.
ALTERNATE_SHARED = (("prep", "tool"), ("prep", "tool_offset"), ("cutcond", "spindle_rpm"),
                    ("cutmotion", "feed"), ("cutcond", "coolant"))

def key(t: str, n: int) -> str:
    return f"{t}:{n}"


def present_operations(module_params: dict) -> list[int]:
    """Numbers n whose cutmotion:n is present, in order; every n must have a template slot."""
    numbers = []
    if not isinstance(module_params, dict):
        raise EngineError(f"module_params = {module_params!r} must be an object of module parameters; fix it in SQL")
    for name, values in module_params.items():
        if not isinstance(values, dict):
            raise EngineError(f"module_params {name!r} = {values!r} must be an object of parameters; fix it in SQL")
        t, _, n = name.partition(":")
        if t == "cutmotion" and "op_present" in values:
            bool_param(values, "op_present", f"module_params.{name}")
        if t == "cutmotion" and values.get("op_present"):
            if not n.isdecimal() or not 1 <= int(n) <= MAX_OPERATIONS:
                raise EngineError(f"module_params {name!r}: the turning templates have operation slots "
                                  f"1…{MAX_OPERATIONS} only; renumber it")
            numbers.append(int(n))
    return sorted(numbers)


def job_passes(params: dict, module_params: dict) -> dict[int, list[Pass]]:
    """The passes of every present operation, by operation number, alternation applied."""
    return planned_passes(params, module_params)[1]


def planned_passes(params: dict, module_params: dict) -> tuple[JobGeometry, dict[int, list[Pass]]]:
    """The job's geometry and passes; every parameter is checked here, once, before it is read."""
    check_job_params(params)
    present = present_operations(module_params)
    for n in present:
        check_operation_params(module_params, n)
    geometry = job_geometry(params)
    check_turnable_from_outside(geometry.edges, f"drawing {params.get('drawing') or '(params.profile)'}")
    passes = {n: operation_passes(geometry, module_params[key("cutmotion", n)], f"module_params.cutmotion:{n}")
              for n in present}
    check_cutting_data(params, module_params, passes)
    pair = alternated_pair(params, module_params, passes)
    if pair:
        first, second = pair
        passes[first] = toolpaths.up_then_across(toolpaths.alternate(passes[first], passes.pop(second)))
    check_job_rapids(geometry, params, module_params, passes)
    return geometry, passes


def alternated_pair(params: dict, module_params: dict, passes: dict) -> tuple[int, int] | None:
    """params.alternate [A, B]: two present ROUGH operations with one tool, machined pass by pass
    alternately (seed 002); operation A carries the passes of both, B emits nothing."""
    pair = params.get("alternate")
    if not pair:
        return None
    if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(n, int) for n in pair) and pair[0] != pair[1]):
        raise EngineError(f"params.alternate = {pair!r} must be two different operation numbers [A, B] or null")
    for n in pair:
        if n not in passes or module_params[key("cutmotion", n)].get("kind") != "ROUGH":
            raise EngineError(f"params.alternate {pair}: operation {n} is not a present ROUGH operation; "
                              "only two ROUGH operations alternate")
    first, second = pair
    for t, name in ALTERNATE_SHARED:
        mine, theirs = module_params[key(t, first)].get(name), module_params[key(t, second)].get(name)
        if mine != theirs:
            raise EngineError(f"params.alternate {pair}: module_params.{key(t, second)}.{name} = {theirs!r} differs "
                              f"from {key(t, first)}.{name} = {mine!r}; the alternated passes run with operation "
                              f"{first}'s tool, spindle, feed and coolant, so make them equal")
    return first, second


def check_job_params(params) -> None:
    """The job parameters the template and the passes read, with their JSON types, or an error naming one."""
    if not isinstance(params, dict):
        raise EngineError(f"params = {params!r} must be an object of job parameters; fix it in SQL")
    for name in ("tool_change_z", "tool_change_x"):
        number_param(params, name, "params")
    number_param(params, "clearance", "params", 0, above=True)
    if params.get("stock_diameter") is not None:
        number_param(params, "stock_diameter", "params", 0, above=True)
        number_param(params, "stock_z_front", "params")
        number_param(params, "stock_z_back", "params")
    bool_param(params, "closed_by_axis", "params")
    integer_param(params, "program_number", "params", 1, ISO_PROGRAM_NUMBERS)
    for name, kind in (("program_name", "program"), ("drawing", "drawing")):   # printed in the program
        if not is_safe(kind, params.get(name)):
            raise EngineError(f"params.{name} = {shown(params.get(name))} must be {NAME_RULES[kind].rule}; {FIX}")


def check_operation_params(module_params: dict, n: int) -> None:
    """A present operation's own parameters: none falls back to the job's defaults (a missing feed
    would be written F0, a missing cutcond no spindle start)."""
    prep, cutcond, cutmotion = (operation_module(module_params, t, n) for t in ("prep", "cutcond", "cutmotion"))
    where = {t: f"module_params.{key(t, n)}" for t in ("prep", "cutcond", "cutmotion")}
    integer_param(prep, "tool", where["prep"], 1, MAX_TOOL)
    # offset 0 cancels the offset (reference §E: T0100, 840D D0): the tool would cut with the
    # turret's position, not its tip's
    integer_param(prep, "tool_offset", where["prep"], 1, MAX_TOOL)
    number_param(cutcond, "spindle_rpm", where["cutcond"], 0, above=True)
    bool_param(cutcond, "coolant", where["cutcond"])
    for t, values in (("prep", prep), ("cutcond", cutcond)):
        if values.get("op_present") is not True:
            raise EngineError(f"{where[t]}.op_present = {values.get('op_present')!r} must be true: operation {n} "
                              f"is present (cutmotion:{n}.op_present); {FIX}")
    check_cutmotion(cutmotion, where["cutmotion"])


def operation_module(module_params: dict, t: str, n: int) -> dict:
    values = module_params.get(key(t, n))
    if values is None:
        raise EngineError(f"module_params.{key(t, n)} is missing: operation {n} is present "
                          f"(cutmotion:{n}.op_present) and needs its {t} parameters; {FIX}")
    return values


def check_cutmotion(cutmotion: dict, where: str) -> None:
    kind = cutmotion.get("kind")
    if kind not in KINDS:
        raise EngineError(f"{where}.kind = {kind!r} is not one of {' | '.join(KINDS)}; {FIX}")
    if kind != "THREAD":
        number_param(cutmotion, "feed", where, 0, above=True)
    if kind == "ROUGH" and not cutmotion.get("paths"):
        number_param(cutmotion, "depth_per_pass", where, 0, above=True)
        number_param(cutmotion, "allowance", where, 0)
    if kind == "THREAD":
        number_param(cutmotion, "thread_pitch", where, 0, above=True)
        number_param(cutmotion, "depth_per_pass", where, 0, above=True)
        if not 0 <= number_param(cutmotion, "infeed_angle", where, 0) <= MAX_INFEED_ANGLE:
            raise EngineError(f"{where}.infeed_angle = {cutmotion['infeed_angle']!r} must be 0 … "
                              f"{MAX_INFEED_ANGLE:g} degrees; {FIX}")


def template_module_params(params: dict, module_params: dict, passes: dict[int, list[Pass]] | None = None) -> dict:
    """The stored module parameters extended for the template: each operation's moves (its passes
    flattened), its number, and its kind in prep (for the operator's comment). An operation
    without passes (cutmotion:n absent or not op_present, alternated into another, or nothing
    to cut) emits nothing, its prep and cutcond rows included. `passes`: job_passes(params,
    module_params) if the caller has them already."""
    if passes is None:
        passes = job_passes(params, module_params)
    cutting = {n for n, found in passes.items() if found}
    extended = {name: dict(values) for name, values in module_params.items()}
    for name, values in extended.items():
        number = name.partition(":")[2]
        if not (number.isdecimal() and int(number) in cutting):
            values["op_present"] = False
    for n in cutting:
        cutmotion = extended[key("cutmotion", n)]
        cutmotion.update(operation=n, moves=flattened(passes[n]))
        extended.setdefault(key("prep", n), {}).update(operation=n, kind=cutmotion["kind"])
    return extended


def flattened(passes: list[Pass]) -> list[Move]:
    """The passes as one list of moves, arcs over 120° split into equal pieces (engine.turning.arc_split)."""
    return with_short_arcs([move for one in passes for move in one])
