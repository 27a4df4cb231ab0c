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
from . import toolpaths
from .arc_split import with_short_arcs
from .moves import Move, Pass
from .names import MAX_OPERATIONS
from .operations import job_geometry, operation_passes

def key(t: str, n: int) -> str:
    return f"{t}:{n}"


def present_operations(module_params: dict) -> list[int]:
    """Numbers n whose cutmotion:n is present, in order; every n must have a template slot."""
    numbers = []
    for name, values in module_params.items():
        if not isinstance(values, dict):
            raise EngineError(f"module_params {name!r} = {values!r} must be an object of parameters; fix it in SQL")
        t, _, n = name.partition(":")
        if t == "cutmotion" and values.get("op_present"):
            if not n.isdecimal() or not 1 <= int(n) <= MAX_OPERATIONS:
                raise EngineError(f"module_params {name!r}: the turning templates have operation slots "
                                  f"1…{MAX_OPERATIONS} only; renumber it")
            numbers.append(int(n))
    return sorted(numbers)


def job_passes(params: dict, module_params: dict) -> dict[int, list[Pass]]:
    """The passes of every present operation, by operation number, alternation applied."""
    geometry = job_geometry(params)
    passes = {n: operation_passes(geometry, module_params[key("cutmotion", n)], f"module_params.cutmotion:{n}")
              for n in present_operations(module_params)}
    pair = alternated_pair(params, module_params, passes)
    if pair:
        first, second = pair
        passes[first] = toolpaths.alternate(passes[first], passes.pop(second))
    return passes


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
    tools = [module_params.get(key("prep", n), {}).get("tool") for n in pair]
    if tools[0] != tools[1]:
        raise EngineError(f"params.alternate {pair}: operations use tools {tools[0]} and {tools[1]}; passes "
                          "alternate without a tool change, so give both the same tool")
    return pair[0], pair[1]


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
    """The passes as one list of moves, arcs over 180° in two halves (engine.turning.arc_split)."""
    return with_short_arcs([move for one in passes for move in one])
