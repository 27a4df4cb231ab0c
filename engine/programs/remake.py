"""Stored jobs made again with their stored, possibly edited, parameters: one job (`engine
instantiate --job ID`) or a range of them (`--jobs FIRST-LAST`), template rows only: no hob
choice, no cutting data. A hobbing job is not trusted as stored (a runner may write jobs in SQL):
its hob, its record parameters and its edited values are checked as a new job's are
(engine.programs.job_checks), a turning job's parameters by the turning model and against its
drawing record (engine.programs.drawing_records). The programs are
checked against the job's machine, stored with the template version they came from, and written
after the database commit. A batch tries every job and names each bad one
(engine.programs.batches). A job of a class without a model (engine.programs.class_jobs) is its
class's rows run with its parameters, read by the verifier and, on a lathe, proved by the turning
simulation against its blank (no drawing record): one stored unverified is verified now, or
refused."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

from msgspec.structs import replace

from ..db.origin import refuse_elsewhere, refuse_unless_made_at, this_plant
from ..errors import EngineError
from ..gears.holding_matching import choose_holding
from ..gears.models import model_for_class
from ..gears.records import Hob, load_gear, load_hobs
from ..hobbing.cylindrical import program_name
from ..hobbing.dialects import refuse_for_dialect
from ..machines.records import Machine, load_machine
from ..machines.work_holding import job_work_holding
from ..memory import no_cycle_collection
from ..nc.layout import NcLayout, class_layout
from ..templates.rows import Template
from ..templates.versions import runnable_template
from ..turning.names import TurningModel
from . import all_models  # noqa: F401  (registers every model)
from .batches import (
    batch_stage,
    checked,
    dry_batch,
    dry_program,
    good_ones,
    planned_or_bad,
    read_only,
    refuse_unfit_output,
)
from .class_jobs import class_job
from .instantiate import store_planned
from .job_checks import check_hobbing_feeds, check_hobbing_job, job_choices
from .job_shape import check_job_shape, job_with_cycle_time, job_with_worm_feed
from .options import NO_FILE, NORMAL_RUN, PLANNING, Output, RunMode
from .outputs import file_layouts, files_after_commit
from .records import Planned, Program
from .storage import Batch, refuse_assumed_blank_file, store_programs
from .verified_run import Workpiece, run_template

if TYPE_CHECKING:
    from ..db.connection import Connection

JOB_COLUMNS = "id, gear_id, gear_class, machine, hob_id, params, module_params"


class Remaker:
    """Machines and templates read once for all the jobs made again in one run."""

    def __init__(self, conn: Connection, draft: bool = False):
        self.conn = conn
        self.draft = draft   # the classes' drafts (an editor trying them), not their released versions
        self._machines: dict[str, Machine] = {}
        self._templates: dict[str, Template] = {}
        self._layouts: dict[str, NcLayout] = {}
        self._hobs: dict[str, Hob] | None = None
        self._modelled: dict[str, bool] = {}

    def remade(self, job: tuple) -> Planned:
        """The job's program planned again, to be written with its class's layout."""
        planned = self._remade(job)
        return replace(planned, layout=self.layout(planned.gear_class, planned.template.version))

    def _remade(self, job: tuple) -> Planned:
        job_id, gear_id, gear_class, machine_name, hob_id, params, module_params = job
        machine = self.machine(machine_name)
        if not self.modelled(gear_class):   # a job of an imported class (instantiate --class): its rows alone
            return class_job(self.template(gear_class), machine, params, module_params)
        if job_id is not None:   # a stored job (a golden test's case names its machine itself)
            check_machine_kind(job_id, gear_class, machine, self.turning(gear_class))
        if machine.kind == "lathe":   # a turning job: its passes are computed from its parameters
            from .turning_jobs import plan_turning_job  # the tool paths: only for turning jobs

            return plan_turning_job(self.conn, gear_class, machine, params, module_params, draft=self.draft,
                                    job_id=job_id)
        model = model_for_class(self.conn, gear_class)
        check_job_shape(job_id, params, module_params)   # a job written by hand: named, not a crash
        stored = job_id is not None   # a stored job is checked as a new one; a golden test's case runs as given
        workpiece = self.workpiece(job_id, gear_id, hob_id, required=stored)
        if stored and workpiece:
            check_hobbing_job(job_id, gear_class, model, workpiece.gear, workpiece.hob, machine, params,
                              module_params)
            refuse_for_dialect(workpiece.gear, model, job_choices(job_id, params), machine)   # as a new job is
            check_program_name(self.conn, job_id, gear_id, params)
            check_work_holding(job_id, workpiece, machine)
            check_hobbing_feeds(job_id, workpiece.gear, workpiece.hob, machine, params, module_params, bounded=False)
        params = job_with_worm_feed(params, model)
        if "cycle_time" in params:   # the time follows feeds edited since
            params = job_with_cycle_time(job_id, params, module_params, model.cut_shape, machine)
        result = run_template(self.template(gear_class), params, module_params, machine, workpiece)
        if stored and workpiece:
            check_hobbing_feeds(job_id, workpiece.gear, workpiece.hob, machine, params, module_params)
        return Planned(gear_id, gear_class, machine_name, hob_id, params, module_params, self.template(gear_class),
                       result)

    def workpiece(self, job_id: int | None, gear_id: int | None, hob_id: str | None,
                  required: bool) -> Workpiece | None:
        """The job's gear and hob as stored now (the simulation proves against the records, not
        against job.params, which may have been edited). A stored hobbing job names both."""
        if (gear_id is None or hob_id is None) and required:
            raise EngineError(f"job {job_id} is a hobbing job without a {'gear' if gear_id is None else 'hob'}: "
                              "its program cannot be proved against the records; make a new job with "
                              "`engine instantiate --gear ID`; nothing stored")
        if gear_id is None or hob_id is None:
            return None
        if self._hobs is None:
            self._hobs = {hob.id: hob for hob in load_hobs(self.conn)}
        hob = self._hobs.get(hob_id)
        if hob is None:
            raise EngineError(f"hob {hob_id!r} of the job does not exist; see `engine hobs list`")
        return Workpiece(load_gear(self.conn, gear_id), hob, job_work_holding(self.conn, job_id))

    def turning(self, gear_class: str) -> bool:
        """Whether the class's model is a turning one (its jobs run on a lathe)."""
        return isinstance(model_for_class(self.conn, gear_class), TurningModel)

    def modelled(self, gear_class: str) -> bool:
        """Whether the class has a model (hobbing, turning) that its jobs were computed with."""
        if gear_class not in self._modelled:
            self._modelled[gear_class] = model_for_class(self.conn, gear_class) is not None
        return self._modelled[gear_class]

    def machine(self, name: str) -> Machine:
        if name not in self._machines:
            self._machines[name] = load_machine(self.conn, name)
        return self._machines[name]

    def layout(self, gear_class: str, version: int) -> NcLayout:
        """The layout of the class's version its programs are made from (one per class here)."""
        if gear_class not in self._layouts:
            self._layouts[gear_class] = class_layout(self.conn, gear_class, version)
        return self._layouts[gear_class]

    def template(self, gear_class: str) -> Template:
        if gear_class not in self._templates:
            self._templates[gear_class] = runnable_template(self.conn, gear_class, self.draft)
        return self._templates[gear_class]


def check_machine_kind(job_id: int, gear_class: str, machine: Machine, turning: bool) -> None:
    """A turning class's job runs on a lathe, a hobbing class's on a hobbing machine: a job stored
    with the other kind would run one model's template on the other machine."""
    if turning != (machine.kind == "lathe"):
        wanted = "a lathe" if turning else "a hobbing machine"
        raise EngineError(f"job {job_id}: machine {machine.name} is a {machine.kind}, class {gear_class!r} runs on "
                          f"{wanted}; correct job.machine; nothing stored")


def check_work_holding(job_id: int, workpiece: Workpiece, machine: Machine) -> None:
    """A stored job's work-holding is held to a new job's tests (engine.gears.holding_matching):
    one too large for the gear's root is refused by name before the simulation."""
    holding = workpiece.holding
    if holding is not None:
        try:
            choose_holding(workpiece.gear, workpiece.hob, machine, [holding], holding.id)
        except EngineError as refusal:
            raise EngineError(f"job {job_id}: {refusal}; nothing stored") from None


def check_program_name(conn: Connection, job_id: int, gear_id: int, params: dict) -> None:
    """A hobbing job's program may be renamed (a part number), but never to another gear's
    program name, GEAR<id> or the name another gear's job carries: its file would replace that
    gear's program on the control (names compared as the control does, ignoring case)."""
    name = params.get("program_name")
    other = re.fullmatch(r"GEAR(\d+)", name, re.IGNORECASE) if isinstance(name, str) else None
    owner = int(other.group(1)) if other else _other_gear_named(conn, name, gear_id)
    if owner is not None and owner != gear_id:
        raise EngineError(f"program name {name!r} of job {job_id} (gear {gear_id}) is the name of gear "
                          f"{owner}'s program; correct job.params (e.g. {program_name(gear_id)}) "
                          f"or make a new job with `engine instantiate --gear {gear_id}`; nothing stored")


def _other_gear_named(conn: Connection, name, gear_id: int) -> int | None:
    row = conn.execute("SELECT gear_id FROM job WHERE upper(params ->> 'program_name') = upper(%s) "
                       "AND gear_id <> %s ORDER BY id LIMIT 1", (name, gear_id)).fetchone()
    return row[0] if row else None


def instantiate_job(conn: Connection, job_id: int, *, output: Output = NO_FILE, mode: RunMode = NORMAL_RUN) -> Program:
    """Instantiate a stored job again with its stored (possibly edited) parameters, its file
    written to `output`. With `mode.dry_run`, the same checks, nothing stored
    (engine.programs.batches): the program returned. The batch fields of `mode` do not apply."""
    refuse_unfit_output(output, mode)
    if mode.dry_run:
        with read_only(conn):
            return dry_program(conn, Remaker(conn, mode.draft).remade(_stored_job(conn, job_id)), job_id)
    with files_after_commit(conn, output) as files:
        job = _stored_job(conn, job_id)
        program = store_planned(conn, [Remaker(conn, mode.draft).remade(job)], files, existing_job=job_id)[0]
    return program


def _stored_job(conn: Connection, job_id: int) -> tuple:
    job = conn.execute(f"SELECT {JOB_COLUMNS} FROM job WHERE id = %s", (job_id,)).fetchone()
    if job is None:
        raise EngineError(f"job {job_id} does not exist; `engine jobs list` shows what does")
    refuse_elsewhere(conn, "job", job_id, "make and send it")
    return job


def instantiate_jobs(conn: Connection, first: int | None = None, last: int | None = None, *,
                     output: Output = NO_FILE, mode: RunMode = NORMAL_RUN) -> Batch:
    """Every stored job with first ≤ id ≤ last made again, every one tried: all programs stored,
    or none if any job is bad (BadBatch names each); with `mode.skip_bad` the good ones are stored
    and the bad ones listed in Batch.skipped. Files are written to `output` after the COMMIT.
    `mode.dry_run`: what would be stored, nothing stored. `mode.progress(stage, done, total)` as
    the jobs are made (one process: `mode.workers` plans gears, not jobs)."""
    with batch_stage(conn, output, mode) as files, no_cycle_collection():   # making and storing build the batch
        good, skipped = good_ones(_remade_jobs(conn, first, last, mode), "job", mode.skip_bad)
        if mode.dry_run:
            return dry_batch([item for _, item in good], skipped)
        for _, item in good:
            refuse_assumed_blank_file(item.name, item.assumed_blank, output.out)
        files.plan([(item.name, item.lines) for _, item in good], file_layouts([item for _, item in good]))
        batch = store_programs(conn, [item for _, item in good], [job_id for job_id, _ in good], output.out, files)
    return replace(batch, skipped=skipped)


def _remade_jobs(conn, first: int | None, last: int | None, mode: RunMode) -> list:
    """(job id, its program encoded for storage), or Bad with its reason, for each stored job with
    first ≤ id ≤ last, in job order."""
    jobs = conn.execute(f"SELECT {JOB_COLUMNS} FROM job WHERE id BETWEEN %s AND %s ORDER BY id",
                        (first if first is not None else 0, last if last is not None else 2**62)).fetchall()
    if not jobs:
        raise EngineError(f"no jobs with ids in {first or 'the start'}…{last or 'the end'}")
    remaker, here = Remaker(conn, mode.draft), this_plant(conn)
    return [_remade_in_batch(remaker, here, job, done, len(jobs), mode.progress) for done, job in enumerate(jobs, 1)]


def _remade_in_batch(remaker: Remaker, here: int, job: tuple, done: int, total: int, progress):
    """(job id, its program encoded for storage), or Bad with its reason: the batch goes on. A job
    another plant made is bad here (engine.db.origin): it is made there, on its own gear."""
    def made() -> tuple:
        refuse_unless_made_at(here, "job", job[0], "make and send it")
        return job[0], checked(remaker.remade(job)).encoded(with_job=False)

    outcome = planned_or_bad("job", job[0], made)
    if progress:
        progress(PLANNING, done, total)
    return outcome
