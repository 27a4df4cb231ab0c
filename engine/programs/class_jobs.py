"""Jobs of a class without a model (issue 17): `engine instantiate --class C --params P.json`.

A class imported from a proven NC program (`engine import-nc`) has its rows and the parameter
values it was imported with (gear_class.import_params), but no model that computes a job from a
gear (hobbing) or a drawing (turning). Its job is those values, with the ones the user gives in
their place: with the imported values its program is the imported file again, with new ones exactly
the words bound to them change. A name the class was not imported with is refused, naming the
known ones: a typo must not silently leave a value as it was.

The program is read by the machine's verifier (engine.programs.verified_run) before anything is
stored. A lathe program is also proved by the turning simulation without a drawing record
(engine.simulation.turning.undrawn): against the blank the job's parameters state
(stock_diameter, stock_z_front, stock_z_back, given with --params like program_name, all three
or none) or else the blank its program implies; what it cannot check without a drawing is in
the program's notes. Proved, it is written to a file like any other. A hobbing program must be
proved by the simulation against a gear and a hob, which such a job has not, so no hobber makes
one. With `unverified` the program is stored without the verifier's reading, for a dialect the
verifier does not know or a program it refuses: its record and its lineage line say UNVERIFIED
(program.unverified), and it is never written to a file for the machine, because a program that
reaches the machine must be one the verifier read. Made again (`instantiate --job`,
engine.programs.remake) the job is verified then, or refused.
"""
from __future__ import annotations

import ast
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..gears.models import model_for_class
from ..library.nc_params import bindings, values
from ..machines.records import Machine, load_machine
from ..names import checked
from ..nc.layout import NcLayout, class_layout
from ..nc.lineage import refuse_lineage_shaped
from ..nc.tokens import NUMBER, tokenise
from ..simulation.turning import BLANK_PARAMS
from ..templates.decision_table import compiled_template
from ..templates.rows import Template
from ..templates.versions import runnable_template
from ..turning.names import TurningModel
from ..verifier.grammar import DIALECTS
from . import all_models  # noqa: F401  (registers every model)
from .batches import dry_program, read_only, refuse_unfit_output
from .instantiate import store_planned
from .options import NO_FILE, NORMAL_RUN, Output, RunMode
from .outputs import files_after_commit
from .records import Planned, Program
from .verified_run import class_work, run_template

if TYPE_CHECKING:
    from ..db.connection import Connection

PROGRAM_NAME = "program_name"   # the job's program name: given or not, whatever the class was imported with
IMPORT_PARAMS = "SELECT import_params FROM gear_class WHERE name = %s"
MACHINES = "SELECT name FROM machine ORDER BY name"
NEVER_WRITTEN = ("an unverified program is never written to a file for the machine (a program that reaches the "
                 "machine is one the verifier read)")


class ClassJob(msgspec.Struct, frozen=True):
    """What `instantiate --class` made: the program (stored, or a dry run's), and which parameters
    the file gave and which took the class's imported values."""
    program: Program
    machine: str
    given: tuple[str, ...]
    taken: tuple[str, ...]


def instantiate_class(conn: Connection, gear_class: str, given: dict, *, machine: str | None = None,
                      source: str = "parameters", output: Output = NO_FILE, mode: RunMode = NORMAL_RUN,
                      unverified: bool = False) -> ClassJob:
    """A job of the class with the parameters `given` (JSON of import-nc's --params, either form),
    its program verified for `machine` (or, `unverified`, not read), stored with the job and written
    to `output` after the COMMIT. `mode.draft`: the class's draft; `mode.dry_run`: the same checks,
    nothing stored. The batch fields of `mode` do not apply."""
    refuse_unfit_output(output, mode)
    refuse_unverified_file(unverified, output.out)
    if mode.dry_run:
        with read_only(conn):
            planned, taken = _planned(conn, gear_class, given, machine, source, mode.draft, unverified)
            return ClassJob(dry_program(conn, planned, None), planned.machine, tuple(given), taken)
    with files_after_commit(conn, output) as files:
        planned, taken = _planned(conn, gear_class, given, machine, source, mode.draft, unverified)
        program = store_planned(conn, [planned], files)[0]
    return ClassJob(program, planned.machine, tuple(given), taken)


def refuse_unverified_file(unverified: bool, out) -> None:
    if unverified and out is not None:
        raise EngineError(f"--unverified with an output folder or --out {out}: {NEVER_WRITTEN}; leave out --out "
                          "(and the machine's out in the config file); nothing stored")


def _planned(conn: Connection, gear_class: str, given: dict, machine_name: str | None, source: str, draft: bool,
             unverified: bool) -> tuple[Planned, tuple[str, ...]]:
    imported = _imported_values(conn, gear_class)
    refuse_modelled(conn, gear_class)
    machine = class_machine(conn, machine_name)
    if not unverified:
        refuse_unread_dialect(machine)
    params, taken = job_params(gear_class, imported, values(given, source), source)
    template = runnable_template(conn, gear_class, draft)
    refuse_other_addresses(template, given, source)
    layout = class_layout(conn, gear_class, template.version)   # its version's line ending and final newline
    if unverified:
        return _unverified_job(template, machine, params, layout), taken
    return class_job(template, machine, params, {}, layout), taken


def _imported_values(conn: Connection, gear_class: str) -> dict:
    row = conn.execute(IMPORT_PARAMS, (gear_class,)).fetchone()
    if row is None:
        raise EngineError(f"class {gear_class!r} does not exist; see `engine template list`")
    return values(row[0] or {}, f"class {gear_class}'s imported parameters")


def refuse_modelled(conn: Connection, gear_class: str) -> None:
    """A class with a model makes its jobs from what the model reads: a gear or a drawing."""
    model = model_for_class(conn, gear_class)
    if isinstance(model, TurningModel):
        raise EngineError(f"class {gear_class!r} is a turning class: its jobs come from drawings "
                          "(engine import-dxf FILE.dxf, then engine instantiate --job ID), not from --class")
    if model is not None:
        raise EngineError(f"class {gear_class!r} has a hobbing model: its jobs are made from gears "
                          "(engine instantiate --gear ID), not from --class")


def class_machine(conn: Connection, name: str | None) -> Machine:
    """The machine record; a hobber is refused: its programs are proved against a gear and hob."""
    if name is None:
        known = ", ".join(row[0] for row in conn.execute(MACHINES))
        raise EngineError(f"give the machine with --machine NAME (known machines: {known or 'none'}) or set "
                          "machine in the config file")
    machine = load_machine(conn, name)
    if machine.kind == "hobber":
        raise EngineError(f"machine {name} is a hobbing machine: its programs are proved by the simulation against "
                          "a gear and a hob, which a class job has not; make hobbing jobs with "
                          "`engine instantiate --gear ID`, or give a lathe with --machine")
    return machine


def refuse_unread_dialect(machine: Machine) -> None:
    """The verifier reads only the dialects it has a grammar for: anything else is refused unread."""
    if (machine.kind, machine.dialect) not in DIALECTS:
        known = ", ".join(f"{kind}/{dialect}" for kind, dialect in DIALECTS)
        raise EngineError(f"machine {machine.name} is a {machine.kind} with dialect {machine.dialect!r}, which the "
                          f"verifier does not read (known: {known}); nothing stored (--unverified stores the "
                          "program unread, never written to a file)")


def job_params(gear_class: str, imported: dict, given: dict, source: str) -> tuple[dict, tuple[str, ...]]:
    """The job's parameters (the imported values, the given ones in their place, and a program
    name) and the names that took the imported value."""
    unknown = sorted(set(given) - set(imported) - {PROGRAM_NAME, *BLANK_PARAMS})
    if unknown:
        known = ", ".join(sorted(set(imported) | {PROGRAM_NAME, *BLANK_PARAMS}))
        raise EngineError(f"{source}: {', '.join(map(repr, unknown))} {'is' if len(unknown) == 1 else 'are'} not a "
                          f"parameter of class {gear_class} (its parameters: {known}); nothing stored")
    _refuse_other_kinds(gear_class, imported, given, source)
    params = {**imported, **given}
    refuse_partial_blank(params, source)
    params.setdefault(PROGRAM_NAME, default_program_name(gear_class))
    checked("program", params[PROGRAM_NAME], "program_name",
            f"give {PROGRAM_NAME} in the parameters file; nothing stored")
    return params, tuple(name for name in imported if name not in given)


def refuse_partial_blank(params: dict, source: str) -> None:
    """The blank is stated whole (its diameter and both ends, mm) or not at all: a diameter
    without its ends cannot be placed in Z, and ends alone say nothing of the material."""
    stated = [name for name in BLANK_PARAMS if name in params]
    if stated and len(stated) != len(BLANK_PARAMS):
        missing = ", ".join(name for name in BLANK_PARAMS if name not in params)
        raise EngineError(f"{source}: the blank needs {', '.join(BLANK_PARAMS)} together (mm; the diameter, the "
                          f"front face's Z and the back end's Z); {missing} missing; nothing stored")


def default_program_name(gear_class: str) -> str:
    """The program name of a job whose class was imported without one: the class name in capitals,
    made an 840D program name (§A1: two letters, or _ and a letter, first; at most 24 characters)
    for every class name import-nc accepts: `_` before one whose second character is no letter
    (c_1 → _C_1, c → _C), and cut to 24 characters."""
    name = gear_class.upper()
    if not name[1:2].isalpha():
        name = "_" + name
    return name[:24]


def refuse_other_addresses(template: Template, given: dict, source: str) -> None:
    """A bound form (`{"value": 100, "addresses": ["S"]}`) asks for the value at those addresses,
    but which words a parameter changes was fixed when the class was imported: a bound form naming
    other addresses is refused, not made at the class's addresses without a word."""
    for name, binding in bindings(given, source).items():
        bound_at = bound_addresses(template, name)
        if binding.addresses is not None and binding.addresses != bound_at:
            raise EngineError(f"{source}: {name} is bound at {_spelled(bound_at)} in class {template.gear_class}, "
                              f"not {' '.join(sorted(binding.addresses))}; give the plain form{_as_list(bound_at)}; "
                              "nothing stored")


def bound_addresses(template: Template, name: str) -> frozenset:
    """The addresses (upper case; None for a number after no address) of the words the class's
    rows bind to parameter `name`. The import made each bound number a replacement field naming
    the parameter (engine.library.nc_rows), so the address is the one the NC tokeniser gives the
    number in that field's place."""
    return frozenset().union(*(_field_addresses(row.o, name) for row in template.rows if row.o))


def _field_addresses(o: str, name: str) -> set:
    """The addresses of the fields naming `name` in the f-string row `o` (none in another row):
    each field is written as the number 1, and the tokens over a field's place give its address."""
    try:
        parts = ast.parse(o, mode="eval").body
    except SyntaxError:
        return set()
    if not isinstance(parts, ast.JoinedStr):
        return set()
    line, places = "", set()
    for part in parts.values:
        if isinstance(part, ast.FormattedValue) and name in {node.id for node in ast.walk(part)
                                                              if isinstance(node, ast.Name)}:
            places.add(len(line))
        line += str(part.value) if isinstance(part, ast.Constant) else "1"   # an f-string's text is str
    return _addresses_at(line, places)


def _addresses_at(line: str, places: set) -> set:
    """The addresses of the number tokens of `line` that cover one of the character positions."""
    addresses, start = set(), 0
    for token in tokenise(line):
        end = start + len(token.text)
        if token.kind == NUMBER and any(start <= place < end for place in places):
            addresses.add(token.address)
        start = end
    return addresses


def _spelled(addresses: frozenset) -> str:
    named = " ".join(sorted(address for address in addresses if address))
    if None in addresses:
        named = f"{named} and numbers after no address" if named else "numbers after no address"
    return named or "no word"


def _as_list(addresses: frozenset) -> str:
    """The bound form that matches the class, when there is one (a number after no address has none)."""
    if not addresses or None in addresses:
        return ""
    return " or " + "[" + ", ".join(f'"{address}"' for address in sorted(addresses)) + "]"


def _kind(value) -> str:
    return "text" if isinstance(value, str) else "yes/no" if isinstance(value, bool) else \
        "number" if isinstance(value, (int, float)) else type(value).__name__


def _refuse_other_kinds(gear_class: str, imported: dict, given: dict, source: str) -> None:
    """A value of another kind than the imported one (text for a number) cannot be written in
    its words' spelling: said naming the parameter, not as the row's formatting error."""
    for name, value in given.items():
        if name in imported and _kind(value) != _kind(imported[name]):
            raise EngineError(f"{source}: {name} = {value!r} is {_kind(value)}, but class {gear_class} was imported "
                              f"with {_kind(imported[name])} {imported[name]!r}; nothing stored")


def class_job(template: Template, machine: Machine, params: dict, module_params: dict,
              layout: NcLayout = NcLayout()) -> Planned:
    """The class's program for the job, read by the machine's verifier (a new job, or a stored one
    made again by engine.programs.remake)."""
    if machine.kind == "hobber":
        raise EngineError(f"class {template.gear_class} has no hobbing model: a program for hobbing machine "
                          f"{machine.name} must be proved by the simulation against a gear and a hob; nothing stored")
    work = class_work(params) if machine.kind == "lathe" else None
    result = run_template(template, params, module_params, machine, work)
    assumed = machine.kind == "lathe" and not all(name in params for name in BLANK_PARAMS)
    return Planned(None, template.gear_class, machine.name, None, params, module_params, template, result,
                   notes=list(work.notes) if work else [], layout=layout, assumed_blank=assumed)



def _unverified_job(template: Template, machine: Machine, params: dict, layout: NcLayout) -> Planned:
    """The class's program not read by any verifier: stored marked UNVERIFIED, never written."""
    result = compiled_template(template).run(params, {})
    refuse_lineage_shaped(params[PROGRAM_NAME], result.lines)
    return Planned(None, template.gear_class, machine.name, None, params, {}, template, result,
                   notes=[f"UNVERIFIED: no verifier read this program; {NEVER_WRITTEN}"], layout=layout,
                   unverified=True)
