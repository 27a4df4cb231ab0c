"""The proof a new program gets, run again on a stored program's rendering (issue 26, finding 9).

A program whose stored lines are exactly the rendering of its version with its job is not yet
evidence: a runner can store a job by hand (n0 = 1240 r/min on a hobber whose hob spindle
turns at most 1000 r/min) and, through program_submission, the very program that job renders.
The lines match; no verifier ever read them. So the check (engine.programs.rendering) proves the
rendered lines now, as engine.programs.verified_run proves a program before it is stored: the
machine's verifier (docs/reference/hobbing.md, machine limits), then on a hobber the simulation
against the gear and hob records, on a lathe (a drawing's job) the turning simulation against the
job's records; a hobbing job is also held to a new job's bounds (engine.programs.job_checks, as
`instantiate --job` holds it: its hob, its record parameters, its hob speed and feeds). A
rendering the proof refuses is REFUSED with the proof's one-line reason. A
program stored UNVERIFIED (instantiate --class --unverified) is not proved: its record and its
lineage line already say no verifier read it, and it is never written to a file."""
from __future__ import annotations

from collections.abc import Callable

from ..errors import EngineError
from ..machines.records import Machine
from ..templates.rows import Template
from ..verifier import verify_program
from .verified_run import TurningWork, Workpiece, from_drawing, prove, prove_lathe

NOTHING_STORED = "; nothing stored"   # the proof's words for a new program; a stored one is already stored


def proof_refusal(lines: list[str], machine: Machine, template: Template, params: dict, module_params: dict,
                  workpiece: Workpiece | None, job_checks: Callable[[], None] | None = None) -> str | None:
    """Why the proof refuses the rendered `lines` (template output, no lineage line), in one line,
    or None when it passes. `params`, `module_params`: the job's as stored; `workpiece`: its gear
    and hob records (None for a job without both, or of an imported class: a hobber refuses it);
    `job_checks`: a stored hobbing job's checks as `instantiate --job` runs them (engine.programs.
    job_checks: its hob, its record parameters, its hob speed and feeds within a new job's bounds)."""
    name = params.get("program_name") if isinstance(params, dict) else None
    name = name if isinstance(name, str) else None
    try:
        if job_checks is not None:
            job_checks()
        verify_program(lines, machine, name)
        if machine.kind == "hobber":
            prove(lines, machine, workpiece, name or "the program")
        elif machine.kind == "lathe" and from_drawing(template, params):
            prove_lathe(lines, machine, TurningWork(params, module_params), name or "the program")
    except EngineError as refusal:
        return " ".join(str(refusal).removesuffix(NOTHING_STORED).split())
    return None

