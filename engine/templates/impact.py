"""What a release would change on the shop floor (issue 15): every stored job of a class and of
its descendants made again with the draft template and compared with its program from the
released version. Template rows only (as engine.programs.remake makes a stored job again,
without the verifier and the simulation, which the gate does not need to see a line change).

The released program is the job's latest stored one (its lineage line left out) when it was made
from the released version from the job's current parameters; otherwise the released template is
evaluated too. The draft is evaluated as if it had the released version number, so the
`; TEMPLATE class vN` line does not count as a change. Jobs with identical parameters and the same
released program are grouped by the database and evaluated once: 10,000 stored jobs of a class
take seconds (bench/impact.py)."""
from __future__ import annotations

import difflib
import json
from dataclasses import dataclass, field, replace

from ..errors import EngineError
from ..gears.models import model_for_class
from ..gears.records import load_machine
from .decision_table import compiled_template
from .rows import Template
from .versions import draft_template, released_template

DIFFS_SHOWN = 5   # unified diffs the CLI prints (all of them with --json)

# The class and its descendants.
TREE = """
WITH RECURSIVE tree(name, depth) AS (
    SELECT name, 0 FROM gear_class WHERE name = %s
    UNION ALL
    SELECT g.name, t.depth + 1 FROM gear_class g JOIN tree t ON g.parent = t.name WHERE t.depth < 50)
SELECT name FROM tree ORDER BY depth, name"""

# The jobs of the classes, grouped by what their programs are made from, each group with the
# released program its jobs share (NULL: evaluate the released template): the job's latest program
# if it came from the released version (class, version, hash) and the job's current parameters.
JOB_GROUPS = """
WITH released(gear_class, version, hash) AS (SELECT * FROM unnest(%s::text[], %s::int[], %s::text[]))
SELECT j.gear_class, j.machine, j.params::text, j.module_params::text,
       CASE WHEN p.template_version = r.version AND p.template_hash = r.hash
                 AND p.input_hash = job_input_hash(j.params, j.module_params)
            THEN ARRAY(SELECT l.text FROM unnest(p.lines, p.row_ids) AS l (text, row_id) WHERE l.row_id <> -1)
       END AS released_lines,
       array_agg(j.id ORDER BY j.id)
FROM job j
JOIN released r ON r.gear_class = j.gear_class
LEFT JOIN LATERAL (SELECT p.template_version, p.template_hash, p.input_hash, p.lines, p.row_ids
                   FROM program p WHERE p.job_id = j.id ORDER BY p.id DESC LIMIT 1) p ON true
GROUP BY 1, 2, 3, 4, 5
ORDER BY min(j.id)"""


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


@dataclass
class Impact:
    """The impact of releasing a class's draft: jobs examined, programs that change, jobs the
    draft fails for, and the diffs of the changed programs (in job id order)."""
    gear_class: str
    jobs: int = 0
    changed: int = 0
    failures: list[JobFailure] = field(default_factory=list)
    diffs: list[JobDiff] = field(default_factory=list)

    def summary(self) -> dict:
        """What a release records: the counts, the changed and failing job ids."""
        return {"jobs": self.jobs, "changed": self.changed, "failed": len(self.failures),
                "changed_jobs": [diff.job_id for diff in self.diffs][:1000],
                "failed_jobs": [failure.job_id for failure in self.failures][:1000]}


def class_tree(conn, gear_class: str) -> list[str]:
    """The class and its descendants, nearest first."""
    return [row[0] for row in conn.execute(TREE, (gear_class,))]


def impact(conn, gear_class: str) -> Impact:
    """Every stored job of the class and its descendants made with the draft, compared with the
    released program."""
    pairs = _template_pairs(conn, class_tree(conn, gear_class))
    report, inputs = Impact(gear_class), _JobInputs(conn)
    if not pairs:
        return report
    classes = list(pairs)
    versions = [pairs[name][0].version for name in classes]
    hashes = [pairs[name][0].hash for name in classes]
    for group in conn.execute(JOB_GROUPS, (classes, versions, hashes)):
        _compare_group(report, pairs[group[0]], inputs, group)
    return report


def _template_pairs(conn, classes: list[str]) -> dict[str, tuple[Template, Template]]:
    """(released, draft evaluated as the released version) of each class that has a released
    template; the draft is the released one for a class without a draft."""
    pairs = {}
    for name in classes:
        try:
            released = released_template(conn, name)
        except EngineError:
            continue   # a class without rows (an inner node of the tree) has no jobs of its own
        draft = draft_template(conn, name)
        pairs[name] = released, replace(draft, version=released.version, draft=False)
    return pairs


def _compare_group(report: Impact, pair: tuple[Template, Template], inputs: "_JobInputs", group) -> None:
    gear_class, machine, params_text, modules_text, stored_lines, job_ids = group
    report.jobs += len(job_ids)
    released, draft = pair
    if released.hash == draft.hash:
        return   # no draft: nothing changes
    try:
        params, modules = inputs.of(gear_class, machine, params_text, modules_text)
        new_lines = compiled_template(draft).run(params, modules).lines
    except EngineError as error:
        report.failures += [JobFailure(job_id, gear_class, str(error)) for job_id in job_ids]
        return
    old_lines = stored_lines if stored_lines is not None else _released_lines(released, params, modules)
    if old_lines != new_lines:
        report.changed += len(job_ids)
        text = unified_diff(old_lines, new_lines, released)
        report.diffs += [JobDiff(job_id, gear_class, text) for job_id in job_ids]


def _released_lines(released: Template, params: dict, modules: dict) -> list[str] | None:
    """The released template's lines for the job (None if it fails: every draft line is a change)."""
    try:
        return compiled_template(released).run(params, modules).lines
    except EngineError:
        return []


def unified_diff(old: list[str], new: list[str], released: Template) -> str:
    label = f"{released.gear_class} v{released.version}"
    return "\n".join(difflib.unified_diff(old, new, f"{label} (released)", f"{label} + draft", lineterm=""))


class _JobInputs:
    """A stored job's parameters as its template reads them, as engine.programs.remake makes them:
    a hobbing job's cycle time from its stored feeds, a turning job's moves from its passes."""

    def __init__(self, conn):
        self.conn, self.machines, self.shapes = conn, {}, {}

    def of(self, gear_class: str, machine_name: str, params_text: str, modules_text: str) -> tuple[dict, dict]:
        params, modules = json.loads(params_text), json.loads(modules_text or "{}")
        machine = self.machine(machine_name)
        if machine.kind == "lathe":
            from ..turning.model import template_module_params   # the tool paths: only for turning jobs

            return params, template_module_params(params, modules)
        if "cycle_time" in params:
            from ..hobbing.machine_job import with_cycle_time

            params = with_cycle_time(params, modules, self.cut_shape(gear_class), machine)
        return params, modules

    def cut_shape(self, gear_class: str) -> str:
        if gear_class not in self.shapes:
            self.shapes[gear_class] = model_for_class(self.conn, gear_class).cut_shape
        return self.shapes[gear_class]

    def machine(self, name: str):
        if name not in self.machines:
            self.machines[name] = load_machine(self.conn, name)
        return self.machines[name]
