"""Instantiation: a workpiece (or a stored job) → its NC program, checked, stored, written.

gear → class → model + hob + cutting data → job parameters → decision table → result
table → verifier (every line read in the machine's dialect, checked against the machine) →
job and program stored in one transaction, committed → .MPF file (engine.programs.outputs:
written only after the COMMIT).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from msgspec.structs import replace

from ..errors import EngineError
from ..gears.case_base import CUT_KINDS_BY_COUNT, CaseBase, job_cutting_record, single_cut_labels
from ..gears.chip_thickness import chip_cases
from ..gears.feed_marks import bounded_for_marks
from ..gears.hob_matching import matching_hobs
from ..gears.holding_matching import choose_holding
from ..gears.known_materials import material_names, unknown_material
from ..gears.models import model_for_class
from ..gears.process_notes import hunting_tooth_notes
from ..gears.records import Gear, load_gear, load_gears, load_hobs
from ..gears.speed_table import speeds_of
from ..hobbing.choices import Choices, refuse_feed_mode
from ..hobbing.dialects import refuse_for_dialect
from ..hobbing.floor_time import floor_time_notes
from ..machines.records import Machine, hobbing_machine
from ..machines.work_holding import load_work_holdings
from ..memory import no_cycle_collection
from ..nc.layout import NcLayout, class_layout
from ..notes import prefixed
from ..templates.rows import Template
from ..templates.versions import runnable_template
from ..turning.names import TurningModel
from ..verifier import LimitError, check_table_speed
from . import all_models  # noqa: F401  (registers every model)
from .batches import (
    Bad,
    batch_stage,
    checked,
    dry_batch,
    dry_program,
    good_ones,
    planned_or_bad,
    read_only,
    reason_of,
    refuse_unfit_output,
)
from .job_search import attempts, first_that_fits
from .options import NO_FILE, NORMAL_RUN, PLANNING, Output, RunMode
from .outputs import ProgramFiles, file_layouts, files_after_commit
from .records import Planned, Program
from .storage import Batch, store_many, store_one
from .verified_run import Workpiece, run_template

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .streamed import StreamedStore


class Planner:
    """Everything shared by the gears of one run: machine, hob library, templates."""

    def __init__(self, conn: Connection, machine: str | None = None, choices: Choices = Choices(), overrides=None,
                 draft: bool = False):
        self.conn = conn
        self.draft = draft   # the classes' drafts (an editor trying them), not their released versions
        self.machine = hobbing_machine(conn, machine)
        self.hobs = load_hobs(conn)
        self.holdings = load_work_holdings(conn)
        self.case_base = CaseBase.load(conn)
        self.materials = material_names(conn)   # named when a gear's material is not among them
        self._cutting: dict[tuple, tuple] = {}
        self.choices = choices
        self.overrides = overrides or {}
        self._templates: dict[str, Template] = {}
        self._layouts: dict[str, NcLayout] = {}   # each class's line ending and final newline, read with its template
        self._models: dict[str, object] = {}
        self._refused: dict[str, EngineError] = {}   # a class whose model or template failed, once

    def template(self, gear_class: str) -> Template:
        if gear_class not in self._templates:
            self._templates[gear_class] = self._remembering_refusal(gear_class, runnable_template, self.conn,
                                                                    gear_class, self.draft)
            self._layouts[gear_class] = class_layout(self.conn, gear_class, self._templates[gear_class].version)
        return self._templates[gear_class]

    def _remembering_refusal(self, gear_class: str, read, *args):
        """A class refused once is refused again without reading the database (batch workers read none)."""
        if gear_class in self._refused:
            raise self._refused[gear_class]
        try:
            return read(*args)
        except EngineError as error:
            self._refused[gear_class] = error
            raise

    def model(self, gear_class: str):
        if gear_class not in self._models:
            self._models[gear_class] = self._remembering_refusal(gear_class, self._model, gear_class)
        return self._models[gear_class]

    def _model(self, gear_class: str):
        model = model_for_class(self.conn, gear_class)
        if isinstance(model, TurningModel):
            raise EngineError(f"class {gear_class!r} is a turning class: its jobs come from drawings "
                              "(engine import-dxf FILE.dxf), not from gears")
        if model is None:
            raise EngineError(f"gear class {gear_class!r} has no hobbing model (nor has any ancestor)")
        return model

    def plan(self, gear: Gear) -> Planned:
        """The gear's job with the first choice that fits, planned and proved (engine.programs.job_search:
        the model's first choice, then the alternatives a skilled programmer would try)."""
        if gear.gear_class is None:
            raise EngineError(f"gear {gear.id} has no gear class; re-import it to classify it")
        check_machine_fits(gear, self.machine)
        check_material(gear, self.materials)
        model = self.model(gear.gear_class)
        refuse_for_dialect(gear, model, self.choices, self.machine)   # what the machine's control cannot be written
        self.template(gear.gear_class)   # a class refused is not a choice that does not fit: refused before the search
        self.choices.for_unit(1, 1 + len(gear.units), gear.id)   # a mode per unit names the gear's units or none
        hobs = [choice.hob for choice in matching_hobs(gear, self.hobs, purpose=model.hob_purpose,
                                                       shift_travel=model.shift_travel(self.choices))]
        if not model.axial_passes:   # a worm wheel: the feed direction is no choice of its (--worm-feed is)
            refuse_feed_mode(gear, self.choices)
        tried = attempts(hobs, self.choices, gear.module, 1 + len(gear.units), model.axial_passes)
        found = first_that_fits(gear.id, gear.module, tried,
                                lambda attempt: self._planned(gear, model, attempt.hob, attempt.choices))
        found.planned.notes[:0] = found.notes
        if found.notes:   # the job keeps why its hob, feed mode and cut count are not the first choice
            found.planned.cutting = {**(found.planned.cutting or {}), "choice": found.notes[0]}
        return found.planned

    def _planned(self, gear: Gear, model, hob, choices: Choices) -> Planned:
        """The job of one choice (hob, choices), its program verified and proved, or its refusal."""
        assert gear.gear_class is not None   # plan refused a gear without one
        holding = choose_holding(gear, hob, self.machine, self.holdings, choices.fixture).holding
        cutting, case_ids = self.cutting_data(gear, hob)
        if model.hob_purpose != "worm_wheel":     # a worm wheel's plunge or tangential feed has no axial pass
            cutting = bounded_for_marks(cutting, gear, hob, choices.cut_count(gear.module), choices.allowance,
                                        frozenset(name for name, value in self.overrides.items() if value is not None))
        job = model.job(gear, gear.gear_class, hob, self.machine, cutting, choices)
        params = {**job.params, "fixture_id": holding.id if holding else ""}   # `; FIXTURE <id>` (issue 29)
        check_speeds(gear, hob.starts, cutting.hob_speed, self.machine)
        template = self.template(gear.gear_class)
        result = run_template(template, params, job.module_params, self.machine, Workpiece(gear, hob, holding))
        kinds = CUT_KINDS_BY_COUNT[choices.cut_count(gear.module)]
        cutting = cutting.of_cuts(kinds)
        record = job_cutting_record(cutting, gear, hob, kinds, case_ids)
        notes = ([prefixed(f"gear {gear.id}: ", note) for note in single_cut_labels(cutting.notes, len(kinds))]
                 + hunting_tooth_notes(gear, hob)
                 + floor_time_notes(self.machine))
        return Planned(gear.id, gear.gear_class, self.machine.name, hob.id, params, job.module_params, template,
                       result, record, notes, self._layouts[gear.gear_class],
                       work_holding_id=holding.id if holding else None)

    def cutting_data(self, gear: Gear, hob) -> tuple:
        """Cutting data from the nearest cases of the machining history (overrides applied),
        and the ids of the cases they came from; gears alike share one suggestion."""
        key = (gear.module, gear.teeth, gear.material, gear.hardness, gear.quality_grade, hob.id,
               tuple(chip_cases(gear, hob)))   # all the chip bound reads: helix, x, each toothing's teeth and depth
        if key not in self._cutting:
            cutting, proposals, _ = self.case_base.cutting_data(gear, hob, self.machine)
            case_ids = [case_id for proposal in proposals.values() for case_id in proposal.case_ids]
            self._cutting[key] = (cutting.with_overrides(gear, hob, **self.overrides), case_ids)
        return self._cutting[key]


def check_material(gear: Gear, known: list[str]) -> None:
    """A gear whose material table material lacks is refused, never given a default: the
    material's §C speeds bound the hob's (engine.gears.speed_table). A gear with no material
    stated keeps the widest range of the table, with a note (the simulation's)."""
    if (gear.material or "").strip() and speeds_of(gear) is None:
        raise EngineError(unknown_material(f"gear {gear.id}: material {gear.material!r}", gear.material or "", known))


def check_machine_fits(gear: Gear, machine: Machine) -> None:
    if machine.module_max is not None and gear.module > machine.module_max:
        raise LimitError(f"gear {gear.id}: module {gear.module:g} exceeds {machine.name}'s maximum "
                         f"module {machine.module_max:g}; nothing stored")


def check_speeds(gear: Gear, starts: int, hob_speed: float, machine: Machine) -> None:
    """The hob speed within the machine's hob spindle and table speed limits (a new job's, and a
    stored job's made again: engine.programs.job_checks)."""
    if hob_speed > machine.spindle_max:
        raise LimitError(f"gear {gear.id}: hob speed {hob_speed:g} r/min exceeds {machine.name}'s hob spindle "
                         f"maximum {machine.spindle_max:g} r/min; nothing stored")
    check_table_speed(gear.id, gear.teeth, starts, hob_speed, machine)


def instantiate_gear(conn: Connection, gear_id: int, *, machine: str | None = None, choices: Choices = Choices(),
                     overrides: dict | None = None, output: Output = NO_FILE, mode: RunMode = NORMAL_RUN) -> Program:
    """Compute, check and store the program of one gear; write it to `output.out` if given (after
    the COMMIT; an existing file only with `output.force`). With `mode.draft`, from the class's
    draft. With `mode.dry_run`, the same checks, nothing stored (engine.programs.batches): the
    program returned. The batch fields of `mode` do not apply."""
    refuse_unfit_output(output, mode)
    if mode.dry_run:
        with read_only(conn):
            planner = Planner(conn, machine, choices, overrides, mode.draft)
            return dry_program(conn, planner.plan(load_gear(conn, gear_id)), None)
    with files_after_commit(conn, output) as files:
        planner = Planner(conn, machine, choices, overrides, mode.draft)
        planned = planner.plan(load_gear(conn, gear_id))
        program = store_planned(conn, [planned], files)[0]
    return program


def instantiate_gears(conn: Connection, first: int | None = None, last: int | None = None, *,
                      machine: str | None = None, choices: Choices = Choices(), overrides=None,
                      output: Output = NO_FILE, mode: RunMode = NORMAL_RUN) -> Batch:
    """All gears with first ≤ id ≤ last, every one planned: all programs stored, or none if any
    gear is bad (BadBatch names each); with `mode.skip_bad` the good ones are stored and the bad
    ones listed in Batch.skipped. Files are written to `output` after the COMMIT. With
    mode.workers > 1 the gears are planned in that many processes (engine.programs.workers).
    `mode.dry_run`: what would be stored, nothing stored. `mode.progress(stage, done, total)` as
    the gears are planned."""
    with batch_stage(conn, output, mode) as files, no_cycle_collection():   # planning and storing build the batch
        streamed = _streamed_store(conn, mode)
        outcomes = _planned_gears(Planner(conn, machine, choices, overrides, mode.draft), first, last, mode, streamed)
        encoded, skipped = good_ones(outcomes, "gear", mode.skip_bad)
        if mode.dry_run:
            return dry_batch(encoded, skipped)
        files.plan([(item.name, item.lines) for item in encoded], file_layouts(encoded))
        batch = streamed.batch(encoded, output.out, files) if streamed and streamed.used else \
            store_many(conn, encoded, output.out, files)
    return replace(batch, skipped=skipped)


def _streamed_store(conn: Connection, mode: RunMode) -> StreamedStore | None:
    """Where a batch planned in workers stores its slices as they come back (engine.programs.streamed)."""
    if mode.workers <= 1 or mode.dry_run:
        return None
    from .streamed import StreamedStore  # batches across cores only (issue 28: start-up)

    return StreamedStore(conn, mode.skip_bad)


def _planned_gears(planner: Planner, first, last, mode: RunMode, streamed: StreamedStore | None = None) -> list:
    """Each gear's program encoded for storage, or Bad with its reason, in gear order (a gear
    whose record cannot even be completed among them). Planned in workers, each slice is given
    to `streamed` as it comes back."""
    refused: dict[int, str] = {}
    gears = load_gears(planner.conn, first, last, refused)
    if not gears and not refused:
        raise EngineError(f"no gears with ids in {first or 'the start'}…{last or 'the end'}")
    if mode.workers > 1 and len(gears) > 1:
        from .workers import plan_in_workers  # a batch across cores only: multiprocessing (issue 28: start-up)

        planned = plan_in_workers(planner, gears, _plan_in_batch, mode, streamed)
    else:
        planned = [_counted(_plan_in_batch(planner, gear), done, len(gears), mode.progress)
                   for done, gear in enumerate(gears, 1)]
    by_gear = dict(zip([gear.id for gear in gears], planned)) | {gear_id: Bad(reason_of(f"gear {gear_id}", message))
                                                                  for gear_id, message in refused.items()}
    return [by_gear[gear_id] for gear_id in sorted(by_gear)]


def _plan_in_batch(planner: Planner, gear: Gear):
    """The gear's program encoded for storage, or Bad: the batch goes on to name every bad gear."""
    return planned_or_bad("gear", gear.id, lambda: checked(planner.plan(gear)).encoded())


def _counted(outcome, done: int, total: int, progress):
    if progress:
        progress(PLANNING, done, total)
    return outcome


def store_planned(conn: Connection, planned: list[Planned], files: ProgramFiles,
                  existing_job: int | None = None) -> list[Program]:
    """Store the programs (and their jobs, unless `existing_job`); their files are checked now
    and written by `files` after the caller's COMMIT."""
    paths = files.plan([(item.name, item.lines) for item in planned], file_layouts(planned))
    programs = [store_one(conn, item, existing_job, paths.get(item.name)) for item in planned]
    files.replace_texts({program.name: program.lines for program in programs})
    return programs
