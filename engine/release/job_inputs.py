"""A stored job's inputs and proof for the release impact (engine.release.impact): its parameters as
its template reads them, as engine.programs.remake makes them (a hobbing job's cycle time from its
stored feeds, a turning job's moves from its passes), and the proof of a program made for it: the
machine's verifier, then the simulation against the job's records, read before the impact's
workers start (they read no database): a hobbing job's gear and hob as stored, a drawn turning
job's drawing record (its params held to the record, the simulation's blank and profile taken from
it, as engine.programs.turning_jobs does), a class job's lathe program against its blank."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

from ..errors import EngineError
from ..gears.models import model_for_class
from ..gears.records import Gear, Hob, load_gear, load_hobs
from ..machines.records import load_machine
from ..machines.work_holding import WorkHolding, job_work_holding, jobs_work_holdings
from ..nc.lineage import refuse_lineage_shaped
from ..programs.drawing_records import turning_job_drawing
from ..programs.job_shape import job_with_cycle_time
from ..programs.verified_run import TurningWork, class_work
from ..simulation import SimulationError, simulate_program
from ..simulation.turning.drawing import DrawingRecord, proof_params
from ..simulation.turning.run import simulate_turning
from ..verifier import verify_program

if TYPE_CHECKING:
    from ..db.connection import Connection
    from ..machines.records import Machine


class JobInputs:
    """A stored job's parameters as its template reads them, as engine.programs.remake makes them:
    a hobbing job's cycle time from its stored feeds, a turning job's moves from its passes."""

    def __init__(self, conn: Connection):
        self.conn = conn
        self.machines: dict[str, Machine | EngineError] = {}
        self.shapes: dict[str, str | EngineError] = {}   # class -> its model's cut shape
        self.models: dict[str, bool | EngineError] = {}  # class -> whether it has a model (else: class jobs)
        self.gears: dict[int, Gear | EngineError] = {}   # a gear that no longer loads: why, for its proof
        self.hobs: dict[str, Hob] | None = None
        self.drawings: dict[int, DrawingRecord | EngineError] = {}   # job -> its record, or why it has none fit
        self.holdings: dict[int, WorkHolding | None | EngineError] = {}   # job -> its holding (None: the machine's)

    def read_records(self, pending: dict[tuple, int]) -> None:
        """The machines, models, gears, hobs and drawing records that making these job inputs (each
        with a job that has it) and proving their programs read, read now (a record that
        is missing is named by the job's proof, from what was read here)."""
        self._read_holdings([job_id for key, job_id in pending.items() if key[4] is not None and key[5] is not None])
        for key, job_id in pending.items():
            try:
                self._read_for(key, job_id)
            except EngineError:
                pass   # named by the job's proof, from what was kept here

    def _read_holdings(self, job_ids: list[int]) -> None:
        """The work-holdings of the jobs that name a gear and a hob (hobbing jobs), in bulk: one
        query for thousands of jobs (one that fails to load is read again job by job, its reason kept)."""
        try:
            self.holdings.update(jobs_work_holdings(self.conn, job_ids))
        except EngineError:
            pass

    def _read_for(self, key: tuple, job_id: int) -> None:
        gear_class, machine_name, params_text, modules_text, gear_id, hob_id = key
        kind = self.machine(machine_name).kind
        try:
            if self.modelled(gear_class) and kind != "lathe":
                self.cut_shape(gear_class)   # a hobbing job's cycle time, as its template reads it
        except EngineError:
            pass   # kept: named by the job's making, its records read on
        if kind == "hobber" and gear_id is not None and hob_id is not None:
            self.workpiece(job_id, gear_id, hob_id)
            self.holding(job_id)
        elif kind == "lathe" and self.drawn(gear_class, params := json.loads(params_text)):
            self.drawing(job_id, params, json.loads(modules_text or "{}"))

    def without_database(self) -> None:
        """In a worker: the connection it inherits shares the parent's socket, so it is taken away."""
        self.conn = None   # type: ignore[assignment]

    def of(self, job_id: int, gear_class: str, machine_name: str, params_text: str,
           modules_text: str) -> tuple[dict, dict]:
        params, modules = json.loads(params_text), json.loads(modules_text or "{}")
        if not self.modelled(gear_class):   # a class job (instantiate --class): its rows alone, as
            return params, modules          # engine.programs.remake makes it again
        machine = self.machine(machine_name)
        if machine.kind == "lathe":
            from ..turning.model import template_module_params  # the tool paths: only for turning jobs

            return params, template_module_params(params, modules)
        if "cycle_time" in params:   # a job stored by hand of another shape is named, not a crash
            params = job_with_cycle_time(job_id, params, modules, self.cut_shape(gear_class), machine)
        return params, modules

    def prove(self, key: tuple, lines: list[str], job_id: int) -> None:
        """A job's program read by the machine's verifier (its limits: an S beyond the hob spindle, a
        move beyond the travel) and followed by the simulation against the job's stored records, as
        engine.programs.verified_run proves it: EngineError if refused. A hobbing job's against its
        gear and hob as stored (issue 28); a turning job's against its drawing's records, a class
        job's lathe program against its blank without a drawing record (issue 27)."""
        gear_class, machine_name, params_text, modules_text, gear_id, hob_id = key
        machine = self.machine(machine_name)
        params = json.loads(params_text)
        name = params.get("program_name") if isinstance(params, dict) else None
        refuse_lineage_shaped(name if isinstance(name, str) else "the program", lines)   # as verified_run does
        verify_program(lines, machine, name if isinstance(name, str) else None)
        if machine.kind == "hobber":
            self.prove_hobbing(lines, machine, job_id, gear_id, hob_id, name if isinstance(name, str) else None)
        if machine.kind != "lathe" or not isinstance(params, dict):
            return
        modules = json.loads(modules_text or "{}")
        drawn = self.drawn(gear_class, params)   # a class job: against its blank alone
        work = TurningWork(*proof_params(self.drawing(job_id, params, modules), params, modules)) if drawn \
            else class_work(params)
        report = simulate_turning(lines, work.params, work.module_params, machine,
                                  params.get("program_name") or "the program")
        if report.refused:
            raise report.error()

    def prove_hobbing(self, lines: list[str], machine: Machine, job_id: int, gear_id: int | None,
                      hob_id: str | None, name: str | None) -> None:
        """The hobbing simulation of a job's program against its gear and hob records (a stored
        hobbing job names both; one that does not cannot be proved, as engine.programs.remake says)."""
        if gear_id is None or hob_id is None:
            raise EngineError(f"job {job_id} is a hobbing job without a {'gear' if gear_id is None else 'hob'}: "
                              "its program cannot be proved against the records")
        gear, hob = self.workpiece(job_id, gear_id, hob_id)
        report = simulate_program(lines, gear, hob, machine, name or "the program", self.holding(job_id),
                                  first_only=True)   # the gate names the job and why: the first refusal
        if report.refused:
            raise SimulationError(f"gear {gear_id}: {report.error()}")

    def drawn(self, gear_class: str, params) -> bool:
        """A turning job made from a drawing (its class has the turning model), not a class job."""
        return self.modelled(gear_class) and isinstance(params, dict) and "profile" in params

    def drawing(self, job_id: int, params: dict, modules: dict) -> DrawingRecord:
        """The job's drawing record, its params held to it (engine.programs.drawing_records), read once:
        in a worker from what was read before it started. A job without one, or whose params have
        left it, cannot be proved (EngineError, as engine instantiate --job says)."""
        if job_id not in self.drawings:
            try:
                self.drawings[job_id] = turning_job_drawing(self.conn, job_id, params, modules)
            except EngineError as error:
                self.drawings[job_id] = error
        record = self.drawings[job_id]
        if isinstance(record, EngineError):
            raise EngineError(str(record))
        return record

    def workpiece(self, job_id: int, gear_id: int, hob_id: str) -> tuple[Gear, Hob]:
        """The job's gear and hob as stored now, each read once: in a worker from what was read before
        it started. A gear that no longer loads (a record edited since) is kept as its reason."""
        if self.hobs is None:
            self.hobs = {hob.id: hob for hob in load_hobs(self.conn)}
        if hob_id not in self.hobs:
            raise EngineError(f"hob {hob_id!r} of job {job_id} does not exist; see `engine hobs list`")
        if gear_id not in self.gears:
            try:
                self.gears[gear_id] = load_gear(self.conn, gear_id)
            except EngineError as error:
                self.gears[gear_id] = error
        gear = self.gears[gear_id]
        if isinstance(gear, EngineError):
            raise EngineError(str(gear))
        return gear, self.hobs[hob_id]

    def holding(self, job_id: int) -> WorkHolding | None:
        """The job's work-holding, which its program states and is proved against (issue 29), read once."""
        return _kept(self.holdings, job_id, lambda: job_work_holding(self.conn, job_id))

    def cut_shape(self, gear_class: str) -> str:
        return _kept(self.shapes, gear_class, lambda: model_for_class(self.conn, gear_class).cut_shape)

    def modelled(self, gear_class: str) -> bool:
        """Whether the class has a model (hobbing, turning); read before the workers start."""
        return _kept(self.models, gear_class, lambda: model_for_class(self.conn, gear_class) is not None)

    def machine(self, name: str) -> Machine:
        return _kept(self.machines, name, lambda: load_machine(self.conn, name))


def _kept(records: dict, key, read):
    """records[key], read once; a record that does not load is kept as its reason and named again
    each time it is asked for (in a worker too, which reads no database)."""
    if key not in records:
        try:
            records[key] = read()
        except EngineError as error:
            records[key] = error
    found = records[key]
    if isinstance(found, EngineError):
        raise EngineError(str(found))
    return found
