"""A golden test's program made in memory, the way `engine instantiate` would make it (nothing
stored): a gear test plans the gear with the hobbing model, the verifier and the simulation
(engine.programs.instantiate.Planner); a params test runs the template with the given job
parameters on the named machine (engine.programs.remake.Remaker: a lathe computes its passes).

What an expectation may name comes from here too: the job's parameters, the hands as signs
(h_hob, h_gear: +1 right, -1 left, 0 none; hobbing.md §A7) and, for a gear test, the gear
record's fields (gear_<field>) and its further units' (unit<N>_<field>)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import asdict

from ..errors import EngineError
from ..gears.records import Gear, load_gear
from ..hobbing.choices import Choices
from ..programs.instantiate import Planner
from ..programs.records import Planned
from ..programs.remake import Remaker
from ..turning.defaults import DEFAULT_LATHE

if TYPE_CHECKING:
    from ..db.connection import Connection

HAND_SIGNS = {"R": 1, "L": -1}
MODULE_PARAMS_KEY = "module_params"   # a params test's module parameters, inside its params object
CHOICE_FIELDS = set(Choices.__struct_fields__)


class GoldenTest(msgspec.Struct, frozen=True):
    """One row of template_test."""
    id: int
    gear_class: str
    name: str
    gear_id: int | None
    params: dict | None
    choices: dict
    expect: tuple[str, ...]
    description: str = ""

    @property
    def label(self) -> str:
        return f"{self.gear_class}/{self.name}"


def made_program(conn: Connection, test: GoldenTest, draft: bool) -> tuple[Planned, dict]:
    """(the program planned in memory, the names its expectations may read)."""
    if test.gear_id is not None:
        gear = load_gear(conn, test.gear_id)
        planned = _planned_gear(conn, test, gear, draft)
        return planned, {**expectation_names(planned.params), **gear_names(gear)}
    planned = _planned_params(conn, test, draft)
    return planned, expectation_names(planned.params)


def _planned_gear(conn: Connection, test: GoldenTest, gear: Gear, draft: bool) -> Planned:
    if gear.gear_class != test.gear_class:
        raise EngineError(f"gear {gear.id} is of class {gear.gear_class}, not {test.gear_class}")
    choices = dict(test.choices)
    machine = choices.pop("machine", None)
    unknown = sorted(set(choices) - CHOICE_FIELDS)
    if unknown:
        raise EngineError(f"unknown choice {unknown[0]!r} (choices: machine, {', '.join(sorted(CHOICE_FIELDS))})")
    return Planner(conn, machine, Choices(**choices), draft=draft).plan(gear)


def _planned_params(conn: Connection, test: GoldenTest, draft: bool) -> Planned:
    assert test.params is not None   # a test of no gear gives its parameters
    params = dict(test.params)
    module_params = params.pop(MODULE_PARAMS_KEY, None) or {}
    machine = test.choices.get("machine") or params.get("machine") or DEFAULT_LATHE
    unknown = sorted(set(test.choices) - {"machine"})
    if unknown:
        raise EngineError(f"a params test takes only the choice 'machine', not {unknown[0]!r}")
    job = (None, params.get("gear_id"), test.gear_class, machine, params.get("hob_id"), params, module_params)
    return Remaker(conn, draft).remade(job)


def expectation_names(params: dict) -> dict:
    """The job's parameters and the hands as signs."""
    return {**params, "h_hob": HAND_SIGNS.get(params.get("hob_hand") or "", 0),
            "h_gear": HAND_SIGNS.get(params.get("hand") or "", 0)}


def gear_names(gear: Gear) -> dict:
    """The gear record's fields as gear_<field>, its further units' as unit<N>_<field>."""
    names = {f"gear_{key}": value for key, value in asdict(gear).items()
             if key not in ("units", "cutting_speeds")}
    for unit in gear.units:
        names.update({f"unit{unit.unit}_{key}": value for key, value in asdict(unit).items() if key != "unit"})
    return names
