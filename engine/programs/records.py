"""A program in memory and as stored: what instantiation (hobbing and turning alike) hands to
storage and what storage hands back."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

import msgspec

from ..nc.layout import NcLayout, nc_text

if TYPE_CHECKING:
    from ..templates.decision_table import Result
    from ..templates.rows import Template


class Planned(msgspec.Struct):
    """A job computed in memory, with its program, not yet stored."""
    gear_id: int | None
    gear_class: str
    machine: str
    hob_id: str | None
    params: dict
    module_params: dict
    template: Template
    result: Result
    cutting: dict | None = None      # job.cutting: the cutting data chosen and their source
    notes: list = []   # what the operator should know, one line each (bounded feeds, …)
    layout: NcLayout = NcLayout()    # the class's line ending and final newline (gear_class; issue 17)
    unverified: bool = False   # no verifier read it (engine.programs.class_jobs): stored so marked, never written
    # A lathe class job proved against a blank assumed from its own cuts (no stock_* params): stored
    # for review, never written to a file (engine.programs.class_jobs.ASSUMED_BLANK_FILE).
    assumed_blank: bool = False
    work_holding_id: str | None = None   # job.work_holding_id: None, the machine record's fixture (issue 29)

    @property
    def name(self) -> str:
        return str(self.params.get("program_name", f"JOB_{self.gear_id}"))

    @property
    def lines(self) -> list[str]:
        return self.result.lines

    def encoded(self, with_job: bool = True) -> Encoded:
        """For storage; without the job's JSON when only the program is stored (a job made again)."""
        job: tuple[str | None, str | None, str | None] = (
            (json.dumps(self.params), json.dumps(self.module_params), json.dumps(self.cutting or {}))
            if with_job else (None, None, None))
        return Encoded(self.gear_id, self.gear_class, self.machine, self.hob_id, *job, self.template.version,
                       self.template.hash, self.name, self.result.lines, self.result.row_ids,
                       json.dumps(self.result.trace), tuple(self.notes), self.layout, self.assumed_blank,
                       self.work_holding_id)


class Encoded(msgspec.Struct, frozen=True):
    """A planned job as a batch stores it: its JSON already encoded and its template reduced to
    version and hash. Batch workers send this across processes (a few strings, not the objects)."""
    gear_id: int | None
    gear_class: str
    machine: str
    hob_id: str | None
    params: str | None            # None: the job is stored already (made again)
    module_params: str | None
    cutting: str | None
    template_version: int
    template_hash: str
    name: str
    lines: list[str]
    row_ids: list[int]
    trace: str
    notes: tuple = ()
    layout: NcLayout = NcLayout()
    assumed_blank: bool = False   # Planned.assumed_blank: never written to a file
    work_holding_id: str | None = None   # Planned.work_holding_id


class Program(msgspec.Struct, frozen=True):
    """A program made: stored (its ids) or a dry run's (ids None), with its lines, trace, notes and file path."""
    program_id: int | None   # None: a dry run (engine.programs.batches), nothing stored
    job_id: int | None       # None: a dry run of a new job
    name: str
    lines: list[str]
    gear_class: str
    template_version: int
    template_hash: str
    path: str | None = None
    trace: dict | None = None        # engine.templates.trace: why each row emitted or not
    row_ids: list[int] | None = None  # the template row of each line
    notes: tuple = ()                 # what the operator should know, one line each (bounded feeds, …)
    layout: NcLayout = NcLayout()     # the class's line ending and final newline
    unverified: bool = False          # no verifier read it: UNVERIFIED in its lineage line and record

    @property
    def text(self) -> str:
        """The program as its class writes it (an imported class: as its file did, byte for byte)."""
        return nc_text(self.lines, self.layout)
