"""A template run for one job with its program verified for the machine: the one way the result
table of a program that may be stored is made (new gears, stored jobs made again, turning jobs
from drawings), so no route stores lines the verifier has not read."""
from __future__ import annotations

from ..gears.records import Machine
from ..templates.decision_table import Result, compiled_template
from ..templates.rows import Template
from .verifier import verify_program


def run_template(template: Template, params: dict, module_params: dict, machine: Machine) -> Result:
    """Evaluate the decision table and verify the program for the machine (engine.programs.verifier)."""
    result = compiled_template(template).run(params, module_params)
    name = params.get("program_name") if isinstance(params, dict) else None
    verify_program(result.lines, machine, name if isinstance(name, str) else None)
    return result
