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
evaluated once: 10,000 stored jobs of a class take seconds (bench/impact.py)."""
from __future__ import annotations

import difflib
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

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

# Every job of the classes, and whether it has a stored program (whose file a layout change changes).
JOBS = """
SELECT j.id, j.gear_class, j.machine, j.params::text, j.module_params::text,
       EXISTS (SELECT 1 FROM program p WHERE p.job_id = j.id), j.gear_id, j.hob_id
FROM job j
WHERE j.gear_class = ANY(%s::text[])
ORDER BY j.id"""


@dataclass(frozen=True)
class JobDiff:
    job_id: int
    gear_class: str
    diff: str   # unified diff, released → draft


@dataclass(frozen=True)
class JobFailure:
    job_id: int
    gear_class: str
    error: str
    released_makes: bool = False   # the released version makes this job a program that passes the same proof


@dataclass
class LayoutChange:
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


@dataclass
class Impact:
    """The impact of releasing a class's draft: jobs examined, programs that change, jobs the
    draft fails for, and the diffs of the changed programs (in job id order)."""
    gear_class: str
    jobs: int = 0
    changed: int = 0
    failures: list[JobFailure] = field(default_factory=list)
    diffs: list[JobDiff] = field(default_factory=list)
    layouts: dict[str, LayoutChange] = field(default_factory=dict)   # class → its draft's other layout
    proved: int = 0   # distinct changed programs read by the verifier and followed by the simulation

    def summary(self) -> dict:
        """What a release records: the counts, the changed and failing job ids, the layout changes."""
        return {"jobs": self.jobs, "changed": self.changed, "failed": len(self.failures),
                "changed_jobs": [diff.job_id for diff in self.diffs][:1000],
                "failed_jobs": [failure.job_id for failure in self.failures][:1000],
                "layout": [change.as_json() for change in self.layouts.values()]}


def impact(conn: Connection, gear_class: str, workers: int = 1) -> Impact:
    """Every stored job of the class and its descendants made with the draft, compared with the
    released program; the changed programs proved in `workers` processes."""
    pairs = _template_pairs(conn, class_and_descendants(conn, gear_class))
    report = Impact(gear_class, layouts=_layout_changes(conn, pairs))
    if not pairs:
        return report
    made = _Made(conn, pairs)
    jobs = conn.cursor(binary=True).execute(JOBS, (list(pairs),)).fetchall()
    report.proved = made.prove_changed(jobs, workers)
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
    new_lines = made.draft_lines(key, job_id)
    if isinstance(new_lines, EngineError):
        report.failures.append(JobFailure(job_id, gear_class, str(new_lines), made.released_proves(key, job_id)))
        return
    old_lines = made.released_lines(key, job_id)   # rendered now: a stored program may be a forgery
    if same_program(old_lines, new_lines):
        return   # the release does not change this job's program: not proved again
    failure = made.draft_failure(key, job_id)
    if failure is not None:
        report.failures.append(JobFailure(job_id, gear_class, str(failure), made.released_proves(key, job_id)))
        return
    report.changed += 1
    report.diffs.append(JobDiff(job_id, gear_class, made.diff(gear_class, old_lines, new_lines)))


class _Made:
    """The programs of distinct job inputs, made once: with the draft (or its failure) and, where the
    stored program is not the released one, with the released template."""

    def __init__(self, conn: Connection, pairs: dict[str, tuple[Template, Template, int]]):
        self.pairs, self.inputs = pairs, JobInputs(conn)
        self.drafts: dict[tuple, list[str] | EngineError] = {}
        self.releases: dict[tuple, list[str]] = {}
        self.proofs: dict[tuple, EngineError | None] = {}

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

    def draft_lines(self, key: tuple, job_id: int) -> list[str] | EngineError:
        """The draft's lines for the job, or why the draft makes none (its rows fail to run)."""
        if key not in self.drafts:
            try:
                self.drafts[key] = compiled_template(self.pairs[key[0]][1]).run(*self.job_inputs(key, job_id)).lines
            except EngineError as error:
                self.drafts[key] = error
        return self.drafts[key]

    def prove_changed(self, jobs: list, workers: int) -> int:
        """Prove ahead, in `workers` processes, the draft's program of every distinct job input it
        changes (the simulation is most of an impact's time); the records they are proved against are
        read here first, the workers read no database. Returns how many were proved."""
        pending: dict[tuple, int] = {}
        for job_id, gear_class, machine, params_text, modules_text, _, gear_id, hob_id in jobs:
            key = gear_class, machine, params_text, modules_text, gear_id, hob_id
            if key in pending or not self.has_draft(gear_class):
                continue
            lines = self.draft_lines(key, job_id)
            if not isinstance(lines, EngineError) and not same_program(self.released_lines(key, job_id), lines):
                pending[key] = job_id
        self.inputs.read_records(pending)
        proofs = map_in_workers(self._proof_of, list(pending.items()), workers, self.inputs.without_database)
        self.proofs.update(zip(pending, proofs))
        return len(pending)

    def _proof_of(self, pending: tuple) -> EngineError | None:
        key, job_id = pending
        try:
            self.inputs.prove(key, self.drafts[key], job_id)   # type: ignore[arg-type]   # lines: pending only
        except EngineError as error:
            return EngineError(str(error))   # as its message: what a worker sends back is pickled
        return None

    def draft_failure(self, key: tuple, job_id: int) -> EngineError | None:
        """Why the draft's changed program for the job fails its proof (verifier, simulation), or None
        (proved ahead by prove_changed; here if it was not)."""
        if key not in self.proofs:
            self.proofs[key] = self._proof_of((key, job_id))
        return self.proofs[key]

    def released_proves(self, key: tuple, job_id: int) -> bool:
        """The released template makes the job a program the draft's proof accepts (asked only for a
        job the draft fails for: a job that fails with both is an old problem, not the draft's)."""
        try:
            lines = compiled_template(self.released(key[0])).run(*self.job_inputs(key, job_id)).lines
            self.inputs.prove(key, lines, job_id)
        except EngineError:
            return False
        return True

    def released_lines(self, key: tuple, job_id: int) -> list[str]:
        """The released template's lines for the job (none if it fails: every draft line is a change)."""
        if key not in self.releases:
            try:
                self.releases[key] = compiled_template(self.released(key[0])).run(*self.job_inputs(key, job_id)).lines
            except EngineError:
                self.releases[key] = []
        return self.releases[key]


def unified_diff(old: list[str], new: list[str], old_label: str, new_label: str) -> str:
    return "\n".join(difflib.unified_diff(old, new, old_label, new_label, lineterm=""))
