"""A turning job's program in memory: template rows run with the job's parameters and the
passes computed from them, then checked against the lathe and proved by the turning simulation
against the job's drawing record and operations (engine.programs.verified_run). Nothing is stored here."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import EngineError
from ..machines.records import Machine, load_machine
from ..programs.drawing_records import turning_job_drawing
from ..programs.records import Planned
from ..programs.verified_run import TurningWork, run_template
from ..simulation.turning.drawing import proof_params
from ..templates.versions import runnable_template
from ..turning.defaults import DEFAULT_LATHE
from ..turning.model import template_module_params

if TYPE_CHECKING:
    from ..db.connection import Connection

TURNING_CLASS_OF_DIALECT = {"iso": "turning_iso", "840d": "turning_840d"}


def lathe(conn: Connection, name: str | None) -> Machine:
    """The machine record, which must be a lathe."""
    machine = load_machine(conn, name or DEFAULT_LATHE)
    if machine.kind != "lathe":
        lathes = ", ".join(r[0] for r in conn.execute("SELECT name FROM machine WHERE kind = 'lathe' ORDER BY name"))
        raise EngineError(f"machine {machine.name} is a {machine.kind}, not a lathe; use --machine "
                          f"{lathes or DEFAULT_LATHE}")
    return machine


def turning_class(machine: Machine) -> str:
    """The dialect of the machine record picks the template class."""
    if machine.dialect not in TURNING_CLASS_OF_DIALECT:
        raise EngineError(f"machine {machine.name} has dialect {machine.dialect!r}; turning templates exist "
                          f"for {', '.join(TURNING_CLASS_OF_DIALECT)}: set machine.dialect")
    return TURNING_CLASS_OF_DIALECT[machine.dialect]


def plan_turning_job(conn: Connection, gear_class: str, machine: Machine, params: dict, module_params: dict,
                     passes: dict | None = None, draft: bool = False, job_id: int | None = None):
    """→ Planned (engine.programs.records): the program computed and checked, not stored.
    `passes`: the job's passes (model.job_passes) if the caller has them already; `draft`: the class's
    draft, not its released template; `job_id`: a stored job, whose params (checked by the model
    first, so a broken one is named as such) must agree with its drawing record, which the program
    is proved against (the part, blank, tool-change position, materials); None: a job being imported
    (its params are the drawing as just read) or a golden test's case (its params as given)."""
    template = runnable_template(conn, gear_class, draft)
    extended = template_module_params(params, module_params, passes)
    drawing = None if job_id is None else turning_job_drawing(conn, job_id, params, module_params)
    work = TurningWork(*proof_params(drawing, params, module_params)) if drawing else TurningWork(params, module_params)
    result = run_template(template, params, extended, machine, work)
    return Planned(None, gear_class, machine.name, None, params, module_params, template, result)
