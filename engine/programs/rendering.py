"""Is a stored program the rendering of what it names? (issue 26, finding 9)

The database checks what it can of a program on the way in (check_program: its version, its row
ids, its lineage line), but it cannot run a template: a runner who stores through
program_submission by hand can store lines, and a trace, that no template version ever made from
the job (`M3 S900` where the version makes `M3 S246`). Every command that shows or uses a stored
program as evidence (`programs show`, `plot --program`, `explain`, `simulate`, `cases confirm`)
first renders it again here: the rows of the version it records (template_version_rows, compiled
once per process), run with its job's parameters as stored, the engine's lineage line added,
compared line by line, row by row and trace entry by trace entry with what is stored.

Four outcomes (`Rendering.status`), and a fifth for a program another plant made:

* MATCH: the stored lines, row ids and trace are exactly the rendering, and the rendered lines
  pass now the proof a new program gets (engine.programs.rendering_proof: the machine's verifier,
  the hobbing or turning simulation against the records); a program stored UNVERIFIED is not
  proved (it says so itself).
* REFUSED: they are the rendering, but the proof refuses it (a job stored by hand with a hob speed
  over the machine's spindle maximum renders a program no verifier would pass). Not evidence.
* MISMATCH: they are not; the first difference is named. Such a program is never evidence.
* UNCHECKED: the program cannot be rendered again from the records, and is not evidence either:
  its job was edited after it was stored (the job's input hash is no longer the one its lineage
  line shows; the job has no history, so the parameters it was made from are gone), it was stored
  before input hashes were kept, its version's rows were never stored, or the version did not
  render the job now (a run over its time budget on a busy machine). Making it again
  (`engine instantiate --job ID`) gives a program that can be checked.
* PLANT: its id is not of this database's range (engine.db.origin): another plant made it and
  proved it when it made it, on that plant's gear, hob and machine records, and it reached this
  database as history (issue 33; docs/design.md §12). It is never rendered here: this database's
  gear of the same id is another gear (a good program would be REFUSED, or fail on a gear not
  here). A command that needs a proof refuses it, naming the plant to run it at.

The rendering is made as the engine made it (engine.programs.remake): a hobbing job with its
cycle time recomputed from its feeds, a turning job with its passes computed from its drawing's
parameters, a job of an imported class with its rows alone. A hobbing job whose module parameters
are not the shape the engine stores (a job written by hand) is UNCHECKED, named, never a crash
(engine.programs.job_shape). A stored trace must be the rendering's too: a
program stored with none (NULL) since traces were kept is a MISMATCH."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import replace

from ..db.connection import scalar
from ..db.origin import MADE_AT_SQL, MADE_HERE_SQL, made_at, plant_name, this_plant
from ..errors import EngineError
from ..gears.models import model_for_class
from ..gears.records import Hob, load_gear, load_hobs
from ..machines.records import Machine, load_machine
from ..machines.work_holding import job_work_holding
from ..names import shown
from ..nc.lineage import lineage_line, lineage_words, with_lineage
from ..templates.decision_table import compiled_template
from ..templates.rows import Template, TemplateRow
from ..templates.translations import load_translations
from . import all_models  # noqa: F401  (registers every model)
from .job_shape import check_job_shape, job_with_cycle_time

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .verified_run import Workpiece

MATCH, MISMATCH, UNCHECKED, REFUSED = "MATCH", "MISMATCH", "UNCHECKED", "REFUSED"
# A program made at another plant (its id outside this database's range, engine.db.origin): proved
# there when it was made; never rendered or proved here, where its gear, hob and machine are not its own.
PLANT = "PLANT"
NOT_RENDERED = "on show"   # a list's word for a program it did not render (`programs show` renders it)
# What a list of programs says without rendering any (SQL over program p JOIN job j): UNCHECKED
# for one that cannot be rendered again (its job edited since, or stored before input hashes).
# PLANT for one another plant made.
_RENDERABLE = ("CASE WHEN p.input_hash IS NOT NULL AND p.input_hash = job_input_hash(j.params, j.module_params) "
               "THEN 'on show' ELSE 'UNCHECKED' END")
LISTED_RENDERING = f"CASE WHEN NOT ({MADE_HERE_SQL.format(id='p.id')}) THEN '{PLANT}' ELSE {_RENDERABLE} END"
STORED = """
SELECT p.id, p.name, p.gear_class, p.template_version, p.template_hash, p.input_hash, p.draft, p.unverified,
       p.lines, p.row_ids, p.trace, p.job_id, j.machine, j.params, j.module_params,
       job_input_hash(j.params, j.module_params), v.version IS NOT NULL, m.dialect, j.gear_id, j.hob_id,
       CASE WHEN NOT (""" + MADE_HERE_SQL.format(id="j.id") + """) THEN """ + MADE_AT_SQL.format(id="j.id") + """ END
FROM program p JOIN job j ON j.id = p.job_id JOIN machine m ON m.name = j.machine
LEFT JOIN template_version_rows v ON v.gear_class = p.gear_class AND v.version = p.template_version
WHERE p.id = %s"""
VERSION_ROWS = "SELECT rows FROM template_version_rows WHERE gear_class = %s AND version = %s"
# The job locked as confirm_job_cases locks it (a program stored for it meanwhile waits: its foreign
# key shares the row), then its last program: the one confirm_job_cases reads.
LOCK_JOB = "SELECT 1 FROM job WHERE id = %s FOR UPDATE"
LAST_PROGRAM = "SELECT max(id) FROM program WHERE job_id = %s"
REMAKE = "make it again with `engine instantiate --job {job}`"


class Rendering(msgspec.Struct, frozen=True):
    """What the check found for one stored program: MATCH, MISMATCH or UNCHECKED, and why (one line)."""
    program_id: int
    status: str
    reason: str
    plant: int | None = None   # PLANT: the plant that made it

    @property
    def matches(self) -> bool:
        return self.status == MATCH

    @property
    def said(self) -> str:
        """The status and its reason, as `programs show` prints it."""
        return f"{self.status}: {self.reason}"

    def as_dict(self) -> dict:
        plant = {} if self.plant is None else {"plant": self.plant}
        return {"status": self.status, "reason": self.reason, **plant}

    def refuse_unless_matching(self, use: str) -> None:
        """EngineError (exit 1, one line) unless the program is the rendering it names."""
        if self.status == PLANT:
            where = plant_name(self.plant or 0)
            raise EngineError(f"program {self.program_id} was made at {where} (its gear, hob and machine records are "
                              f"the plant's): not re-proved here, so refused as evidence for {use}; run it at {where}")
        if not self.matches:
            raise EngineError(f"program {self.program_id}: {self.status}: {self.reason}; refused as evidence for {use}")


def stored_rendering(conn: Connection, program_id: int) -> Rendering:
    """The stored program compared with its rendering; EngineError if there is no such program."""
    return Renderer(conn).rendering(program_id)


def checked_program(conn: Connection, program_id: int, use: str) -> Rendering:
    """The program's rendering, or EngineError naming MISMATCH or UNCHECKED and `use`."""
    rendering = stored_rendering(conn, program_id)
    rendering.refuse_unless_matching(use)
    return rendering


def checked_last_program(conn: Connection, job_id: int, use: str) -> Rendering | None:
    """The job's last program (what `cases confirm` takes as evidence) checked; None if it has none.
    Call it in the transaction that uses the program: the job stays locked until it ends."""
    conn.execute(LOCK_JOB, (job_id,))
    found = scalar(conn.execute(LAST_PROGRAM, (job_id,)))
    return None if found is None else checked_program(conn, found, use)


class StoredProgram(msgspec.Struct, frozen=True):
    """A program as stored, with what rendering it again needs from its job, version and machine."""
    id: int
    name: str
    gear_class: str
    version: int
    template_hash: str
    input_hash: str | None
    draft: bool
    unverified: bool
    lines: list
    row_ids: list
    trace: dict | None
    job_id: int
    machine: str
    params: dict
    module_params: dict
    job_hash: str
    version_stored: bool
    dialect: str
    gear_id: int | None = None   # the job's gear and hob, which the proof simulates against
    hob_id: str | None = None
    made_at: int | None = None   # the plant whose job it is, when not this database's (docs/design.md §12)


class Renderer:
    """Renders stored programs again, reading each class's model, machine and template version once
    (a list of a thousand programs renders with one query each: engine programs list --check)."""

    def __init__(self, conn: Connection):
        self.conn = conn
        self._templates: dict[tuple[str, int], Template] = {}
        self._models: dict[str, object] = {}
        self._machines: dict[str, Machine] = {}
        self._workpieces: dict[tuple[int, str], Workpiece] = {}
        self._hobs: dict[str, Hob] | None = None
        self._here: int | None = None

    def rendering(self, program_id: int) -> Rendering:
        row = self.conn.execute(STORED, (program_id,)).fetchone()
        if row is None:
            raise EngineError(f"program {program_id} does not exist; see `engine programs list`")
        if self._here is None:
            self._here = this_plant(self.conn)
        if made_at(program_id) != self._here:
            return made_at_plant(program_id)
        return self.compared(StoredProgram(*row))

    def compared(self, stored: StoredProgram) -> Rendering:
        unchecked = _why_unchecked(stored)
        if unchecked:
            return Rendering(stored.id, UNCHECKED, unchecked)
        template = self.template(stored.gear_class, stored.version)
        if template.hash != stored.template_hash:
            return Rendering(stored.id, MISMATCH, f"class {stored.gear_class} v{stored.version}'s stored rows have "
                                                  f"hash {template.hash}, the program records {stored.template_hash}")
        try:
            made, lines, row_ids, trace = self.made(stored, template)
        except EngineError as error:   # not rendered now (a run over its budget on a busy machine, or a job
            # no version renders): nothing to compare, so no evidence either way
            return Rendering(stored.id, UNCHECKED, f"class {stored.gear_class} v{stored.version} did not render job "
                                                   f"{stored.job_id} now ({error}); try again, or "
                                                   f"{REMAKE.format(job=stored.job_id)}")
        difference = _difference(stored, lines, row_ids, trace)
        if difference:
            return Rendering(stored.id, MISMATCH, f"{difference}; the stored lines are not the rendering of class "
                                                  f"{stored.gear_class} v{stored.version} with job {stored.job_id}")
        refusal = None if stored.unverified else self.refusal(stored, template, made)
        if refusal:
            return Rendering(stored.id, REFUSED, f"its lines are the rendering of class {stored.gear_class} "
                                                 f"v{stored.version} with job {stored.job_id}, which the proof a new "
                                                 f"program gets refuses now: {refusal}")
        proved = "" if stored.unverified else ", proved now for the machine"
        return Rendering(stored.id, MATCH, f"its {len(lines)} lines are the rendering of class {stored.gear_class} "
                                           f"v{stored.version} with job {stored.job_id}'s parameters{proved}")

    def refusal(self, stored: StoredProgram, template: Template, made: list) -> str | None:
        """Why the verifier or the simulation refuses the rendered lines now, or None."""
        # the proof's modules, imported only when a program is checked (a plain list stays quick)
        from .job_checks import check_hobbing_feeds, check_hobbing_job
        from .rendering_proof import proof_refusal

        params, module_params, model = stored.params, stored.module_params, self.model(stored.gear_class)
        workpiece = self.workpiece(stored.gear_id, stored.hob_id) if model else None
        if workpiece is not None:   # the job's work-holding, which its program states and is proved against
            workpiece = replace(workpiece, holding=job_work_holding(self.conn, stored.job_id))
        machine = self.machine(stored.machine)
        checks = None
        if workpiece is not None and machine.kind == "hobber":   # the job held to a new job's bounds too
            def checks() -> None:
                check_hobbing_job(stored.job_id, stored.gear_class, model, workpiece.gear, workpiece.hob, machine,
                                  params, module_params)
                check_hobbing_feeds(stored.job_id, workpiece.gear, workpiece.hob, machine, params, module_params)
        return proof_refusal(made, machine, template, params, module_params, workpiece, checks)

    def workpiece(self, gear_id: int | None, hob_id: str | None) -> Workpiece | None:
        """The job's gear and hob as stored now (read once per list), None without both."""
        from .verified_run import Workpiece

        if gear_id is None or hob_id is None:
            return None
        if self._hobs is None:
            self._hobs = {hob.id: hob for hob in load_hobs(self.conn)}
        if hob_id not in self._hobs:
            return None
        if (gear_id, hob_id) not in self._workpieces:
            self._workpieces[gear_id, hob_id] = Workpiece(load_gear(self.conn, gear_id), self._hobs[hob_id])
        return self._workpieces[gear_id, hob_id]

    def template(self, gear_class: str, version: int) -> Template:
        """The class's stored version (with the stored translations of its SQL conditions)."""
        if (gear_class, version) not in self._templates:
            found = scalar(self.conn.execute(VERSION_ROWS, (gear_class, version)))
            rows = tuple(TemplateRow(**row) for row in found)
            self._templates[gear_class, version] = Template(gear_class, version, rows,
                                                            load_translations(self.conn, rows))
        return self._templates[gear_class, version]

    def rendered(self, stored: StoredProgram, template: Template) -> tuple[list, list, dict]:
        """The lines (lineage line included), row ids and trace the engine makes for the job."""
        return self.made(stored, template)[1:]

    def made(self, stored: StoredProgram, template: Template) -> tuple[list, list, list, dict]:
        """The template's lines, then the lines with the lineage line, row ids and trace."""
        params, module_params = self.inputs(stored)
        result = compiled_template(template).run(params, module_params)
        words = lineage_words(stored.id, stored.gear_class, stored.version, stored.template_hash,
                              stored.input_hash or "", stored.draft, stored.unverified)
        lines, row_ids = with_lineage(list(result.lines), list(result.row_ids), lineage_line(words, stored.dialect))
        return list(result.lines), lines, row_ids, json.loads(json.dumps(result.trace))   # as jsonb gives it back

    def inputs(self, stored: StoredProgram) -> tuple[dict, dict]:
        """The job's parameters as the engine gives them to the template (engine.programs.remake)."""
        model, machine = self.model(stored.gear_class), self.machine(stored.machine)
        params, module_params = stored.params, stored.module_params
        if model is None:   # a job of an imported class: its rows alone
            return params, module_params
        if machine.kind == "lathe":   # a turning job: its passes computed from its parameters
            from ..turning.model import template_module_params

            return params, template_module_params(params, module_params)
        check_job_shape(stored.job_id, params, module_params)   # a job written by hand: named, not a crash
        if "cycle_time" in params:   # a hobbing job: the time follows its feeds
            params = job_with_cycle_time(stored.job_id, params, module_params, model.cut_shape, machine)
        return params, module_params

    def model(self, gear_class: str):
        if gear_class not in self._models:
            self._models[gear_class] = model_for_class(self.conn, gear_class)
        return self._models[gear_class]

    def machine(self, name: str) -> Machine:
        if name not in self._machines:
            self._machines[name] = load_machine(self.conn, name)
        return self._machines[name]


def made_at_plant(program_id: int) -> Rendering:
    """What is true of a program another plant made: its stored text and lineage are shown, never
    a MATCH or REFUSED against this database's records."""
    plant = made_at(program_id)
    return Rendering(program_id, PLANT, f"made at {plant_name(plant)}: proved there when it was made; not "
                                        "re-proved here (its gear, hob and machine records are the plant's)", plant)


def _why_unchecked(stored: StoredProgram) -> str | None:
    """Why the program cannot be rendered again from the records, or None."""
    remake = REMAKE.format(job=stored.job_id)
    if stored.made_at is not None:   # a plant's gears, cases and materials are its own, not replicated
        return (f"made at plant {stored.made_at} for that plant's gear {stored.gear_id}, not this database's, and "
                f"proved there: see it with `engine programs show {stored.id}` at plant {stored.made_at}")
    if stored.input_hash is None:
        return f"stored before input hashes were kept, it cannot be rendered again; {remake}"
    if stored.job_hash != stored.input_hash:
        return (f"job {stored.job_id} was edited since (input hash now {stored.job_hash[:8]}, the program's "
                f"{stored.input_hash[:8]}), so the parameters it was made from are gone; {remake}")
    if not stored.version_stored:
        return f"class {stored.gear_class} v{stored.version} was never stored, so it cannot be rendered; {remake}"
    return None


def _difference(stored: StoredProgram, lines: list, row_ids: list, trace: dict) -> str | None:
    """The first difference between the stored program and its rendering, in words, or None."""
    for number, (found, made) in enumerate(zip(stored.lines, lines), 1):
        if found != made:
            return f"line {number} is {shown(found)}, the rendering's {shown(made)}"
    if len(stored.lines) != len(lines):
        return f"it has {len(stored.lines)} lines, the rendering {len(lines)}"
    if list(stored.row_ids) != row_ids:
        number = next(n for n, (a, b) in enumerate(zip(stored.row_ids, row_ids), 1) if a != b)
        return f"line {number} is recorded as template row {stored.row_ids[number - 1]}, the rendering's row " \
               f"{row_ids[number - 1]}"
    if stored.trace is None:   # every program stored since input hashes were kept has its trace
        return "it has no trace stored (NULL), the rendering has one"
    if stored.trace != trace:
        return f"its trace is not the rendering's ({_trace_difference(stored.trace, trace)})"
    return None


def _trace_difference(found: dict, made: dict) -> str:
    if found.get("inputs") != made.get("inputs"):
        return "the inputs it records differ"
    rows = zip(found.get("rows") or [], made.get("rows") or [])
    return next((f"row {b.get('row')}'s entry differs" for a, b in rows if a != b), "its rows differ")
