"""What a release would change on the shop floor (issue 15): every stored job of a class and of
its descendants made again with the draft template and compared with its program from the
released version. Each program the draft changes is proved as a program that is stored is
(engine.programs.verified_run): read by the machine's verifier, and followed by the simulation
against the job's records: a hobbing job's by the hobbing simulation against its gear and hob as
stored (issue 28), a turning job's by the turning simulation (issue 26). A draft whose program for
a stored job fails the proof is named as failing for that job; the gate refuses it where the
released version makes that job a program that passes. A program the draft leaves as it is, is
not proved again: releasing the draft does not change it.

The "before" side is the released version rendered now for the job, never the job's stored
program: a stored program is a record a runner can write by hand (program_submission), and one that
is not its rendering (a MISMATCH: lines equal to the draft's, say) would hide the job's change.
Rendering the released version costs one more template run per distinct job input. The draft is
evaluated with its own version number, as it runs once released (rows may read template_version);
its `; TEMPLATE class vN` line, differing in the number alone, is not a change
(engine.release.version_lines). A draft that only writes its lines with
another layout (line ending, final newline: version_layout_change) changes no line, but the bytes of
every stored program's file of the class: said on its own, with how many programs. Jobs with identical parameters are
evaluated once. With `workers`, forked processes make, compare and prove the distinct job inputs
(the parent reads every record first and gathers the failures and diffs, in job order): 10,000
stored spur jobs, every program changed and proved, take about 9 s with two, 18 s in one process
(bench/impact.py, 2 cores)."""
from __future__ import annotations

import difflib
from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import replace

from ..db.origin import MADE_AT_SQL, MADE_HERE_SQL
from ..errors import EngineError
from ..nc.layout import ENDING_NAMES, NcLayout
from ..programs import all_models  # noqa: F401  (registers every model)
from ..programs.workers import map_in_workers
from ..templates.decision_table import compiled_template
from ..templates.history import layout_change
from ..templates.rows import Template
from ..templates.store import class_and_descendants
from ..templates.versions import draft_template, released_template
from .job_inputs import JobInputs
from .version_lines import same_program

if TYPE_CHECKING:
    from ..db.connection import Connection

DIFFS_SHOWN = 5   # unified diffs the CLI prints (all of them with --json)

# Every job of the classes made in this database, and whether it has a stored program (whose file a
# layout change changes). At a head office the job table also holds its plants' jobs (issue 33,
# docs/design.md §12): they are proved at their plant, against the plant's gears, which the head
# office does not hold (a gear of the same number there is another gear), so they are left out.
JOBS = """
SELECT j.id, j.gear_class, j.machine, j.params::text, j.module_params::text,
       EXISTS (SELECT 1 FROM program p WHERE p.job_id = j.id), j.gear_id, j.hob_id
FROM job j
WHERE j.gear_class = ANY(%s::text[]) AND """ + MADE_HERE_SQL.format(id="j.id") + """
ORDER BY j.id"""
# The plants' jobs of the classes a head office holds as history: counted and said, never re-made.
PLANT_JOBS = """
SELECT """ + MADE_AT_SQL.format(id="j.id") + """, count(*)::int FROM job j
WHERE j.gear_class = ANY(%s::text[]) AND NOT (""" + MADE_HERE_SQL.format(id="j.id") + """)
GROUP BY 1 ORDER BY 1"""


class JobDiff(msgspec.Struct, frozen=True):
    job_id: int
    gear_class: str
    diff: str   # unified diff, released → draft


class JobFailure(msgspec.Struct, frozen=True):
    job_id: int
    gear_class: str
    error: str
    released_makes: bool = False   # the released version makes this job a program that passes the same proof


class LayoutChange(msgspec.Struct):
    """A class whose draft writes its programs with another layout than its released version: the
    files of all its stored programs change bytes, though no line changes."""
    gear_class: str
    old: NcLayout
    new: NcLayout
    programs: int = 0

    def said(self) -> str:
        return (f"layout of {self.gear_class}: {self.old.said} → {self.new.said}: the files of all {self.programs} "
                "stored program(s) change bytes")

    def as_json(self) -> dict:
        return {"class": self.gear_class, "from": _layout_json(self.old), "to": _layout_json(self.new),
                "programs": self.programs}


def _layout_json(layout: NcLayout) -> dict:
    return {"line_ending": ENDING_NAMES[layout.line_ending], "final_newline": layout.final_newline}


class Impact(msgspec.Struct):
    """The impact of releasing a class's draft: jobs examined, programs that change, jobs the
    draft fails for, and the diffs of the changed programs (in job id order)."""
    gear_class: str
    jobs: int = 0
    changed: int = 0
    failures: list[JobFailure] = []
    diffs: list[JobDiff] = []
    layouts: dict[str, LayoutChange] = {}   # class → its draft's other layout
    proved: int = 0   # distinct changed programs read by the verifier and followed by the simulation
    plant_jobs: dict[int, int] = {}   # plant → its jobs of the classes, held here as history, not re-made

    def plants_sentence(self) -> str:
        """The plants' jobs left out, as a sentence of its own ("" without any): JSON's `plants_said`
        and the web's impact line."""
        if not self.plant_jobs:
            return ""
        plants = ", ".join(map(str, self.plant_jobs))
        return (f"{sum(self.plant_jobs.values())} job(s) of plant(s) {plants} not re-made here (their gears are "
                "the plants'); each plant proves its programs when it makes or sends them")

    def plants_said(self) -> str:
        """The same closing the CLI's impact line: "; and …" ("" without any)."""
        return f"; and {self.plants_sentence()}" if self.plant_jobs else ""

    def plants_json(self) -> list[dict]:
        return [{"plant": plant, "jobs": jobs} for plant, jobs in self.plant_jobs.items()]

    def summary(self) -> dict:
        """What a release records: the counts, the changed and failing job ids, the layout changes."""
        return {"jobs": self.jobs, "changed": self.changed, "failed": len(self.failures),
                "changed_jobs": [diff.job_id for diff in self.diffs][:1000],
                "failed_jobs": [failure.job_id for failure in self.failures][:1000],
                "layout": [change.as_json() for change in self.layouts.values()]}


def impact(conn: Connection, gear_class: str, workers: int = 1) -> Impact:
    """Every stored job of the class and its descendants made with the draft, compared with the
    released program; the changed programs proved in `workers` processes."""
    classes = class_and_descendants(conn, gear_class)
    pairs = _template_pairs(conn, classes)
    report = Impact(gear_class, layouts=_layout_changes(conn, pairs),
                    plant_jobs=dict(conn.execute(PLANT_JOBS, (classes,)).fetchall()))
    if not pairs:
        return report
    made = _Made(conn, pairs)
    jobs = conn.cursor(binary=True).execute(JOBS, (list(pairs),)).fetchall()
    report.proved = made.make_all(jobs, workers)
    for job in jobs:
        _compare(report, made, job)
    return report


def _template_pairs(conn: Connection, classes: list[str]) -> dict[str, tuple[Template, Template, int]]:
    """(released, draft, the draft's own version) of each class that has a released template; the
    draft is the released one for a class without a draft."""
    pairs = {}
    for name in classes:
        try:
            released = released_template(conn, name)
        except EngineError:
            continue   # a class without rows (an inner node of the tree) has no jobs of its own
        draft = draft_template(conn, name)
        pairs[name] = released, replace(draft, draft=False), draft.version
    return pairs


def _layout_changes(conn: Connection, pairs: dict[str, tuple[Template, Template, int]]) -> dict[str, LayoutChange]:
    """The classes whose draft has another layout than their released version."""
    changes = {}
    for name, (released, _, draft_version) in pairs.items():
        change = layout_change(conn, name, released.version, draft_version)
        if change is not None:
            changes[name] = LayoutChange(name, *change)
    return changes


def _compare(report: Impact, made: _Made, job) -> None:
    job_id, gear_class, machine, params_text, modules_text, has_program, gear_id, hob_id = job
    report.jobs += 1
    if gear_class in report.layouts and has_program:
        report.layouts[gear_class].programs += 1
    if not made.has_draft(gear_class):
        return   # no draft: nothing changes
    key = gear_class, machine, params_text, modules_text, gear_id, hob_id
    outcome = made.outcome(key, job_id)
    if outcome.failure is not None:
        report.failures.append(JobFailure(job_id, gear_class, outcome.failure, made.released_proves(key, job_id)))
    elif outcome.diff is not None:
        report.changed += 1
        report.diffs.append(JobDiff(job_id, gear_class, outcome.diff))


class _Outcome(msgspec.Struct, frozen=True):
    """What the draft does to the program of one distinct job input, as a worker sends it back (text
    only: it is pickled): why it fails (its rows fail to run, or its changed program fails the
    proof), or the diff of its changed program (None: the release leaves it as it is)."""
    failure: str | None = None
    diff: str | None = None
    proved: bool = False   # its program changed, so it was read by the verifier and simulated


class _Made:
    """The programs of distinct job inputs, made once with the draft and with the released template,
    compared and, where the draft changes them, proved: in `workers` forked processes."""

    def __init__(self, conn: Connection, pairs: dict[str, tuple[Template, Template, int]]):
        self.pairs, self.inputs = pairs, JobInputs(conn)
        self.outcomes: dict[tuple, _Outcome] = {}

    def has_draft(self, gear_class: str) -> bool:
        released, draft, _ = self.pairs[gear_class]
        return released.hash != draft.hash

    def released(self, gear_class: str) -> Template:
        return self.pairs[gear_class][0]

    def diff(self, gear_class: str, old: list[str], new: list[str]) -> str:
        released, _, draft_version = self.pairs[gear_class]
        return unified_diff(old, new, f"{gear_class} v{released.version} (released)",
                            f"{gear_class} v{draft_version} (draft)")

    def job_inputs(self, key: tuple, job_id: int) -> tuple[dict, dict]:
        """The job's parameters and module parameters as its template reads them (key: class,
        machine, params, module params, gear, hob)."""
        return self.inputs.of(job_id, *key[:4])

    def make_all(self, jobs: list, workers: int) -> int:
        """Every distinct job input of a class with a draft made with both templates, compared and,
        where the draft changes its program, proved: in `workers` processes (the evaluation and the
        simulation are nearly all of an impact's time). The templates are compiled and the records
        the proofs read are read here first: the workers read no database. Returns how many
        changed programs were proved."""
        pending: dict[tuple, int] = {}
        for job_id, gear_class, machine, params_text, modules_text, _, gear_id, hob_id in jobs:
            key = gear_class, machine, params_text, modules_text, gear_id, hob_id
            if key not in pending and self.has_draft(gear_class):
                pending[key] = job_id
        for gear_class in {key[0] for key in pending}:
            compiled_template(self.pairs[gear_class][0])
            compiled_template(self.pairs[gear_class][1])
        self.inputs.read_records(pending)
        outcomes = map_in_workers(self._outcome_of, list(pending.items()), workers, self.inputs.without_database)
        self.outcomes.update(zip(pending, outcomes))
        return sum(outcome.proved for outcome in outcomes)

    def outcome(self, key: tuple, job_id: int) -> _Outcome:
        """The draft's outcome for the job input (made by make_all; here if it was not)."""
        if key not in self.outcomes:
            self.outcomes[key] = self._outcome_of((key, job_id))
        return self.outcomes[key]

    def _outcome_of(self, pending: tuple) -> _Outcome:
        key, job_id = pending
        try:
            inputs = self.job_inputs(key, job_id)   # read by both templates (their rows cannot change them)
            new_lines = compiled_template(self.pairs[key[0]][1]).run(*inputs, traced=False).lines
        except EngineError as error:
            return _Outcome(failure=str(error))   # the draft's rows fail to run for the job
        old_lines = self.released_lines(key, inputs)   # rendered now: a stored program may be a forgery
        if same_program(old_lines, new_lines):
            return _Outcome()   # the release does not change this job's program: not proved again
        try:
            self.inputs.prove(key, new_lines, job_id)
        except EngineError as error:
            return _Outcome(failure=str(error), proved=True)
        return _Outcome(diff=self.diff(key[0], old_lines, new_lines), proved=True)

    def released_proves(self, key: tuple, job_id: int) -> bool:
        """The released template makes the job a program the draft's proof accepts (asked only for a
        job the draft fails for: a job that fails with both is an old problem, not the draft's)."""
        try:
            lines = compiled_template(self.released(key[0])).run(*self.job_inputs(key, job_id), traced=False).lines
            self.inputs.prove(key, lines, job_id)
        except EngineError:
            return False
        return True

    def released_lines(self, key: tuple, inputs: tuple[dict, dict]) -> list[str]:
        """The released template's lines for the job's inputs (none if it fails: every draft line is a
        change)."""
        try:
            return compiled_template(self.released(key[0])).run(*inputs, traced=False).lines
        except EngineError:
            return []


def unified_diff(old: list[str], new: list[str], old_label: str, new_label: str) -> str:
    return "\n".join(difflib.unified_diff(old, new, old_label, new_label, lineterm=""))
