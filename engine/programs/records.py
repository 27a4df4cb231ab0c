"""A program in memory and as stored: what instantiation (hobbing and turning alike) hands to
storage and what storage hands back."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..templates.decision_table import Result
    from ..templates.rows import Template


@dataclass(slots=True)
class Planned:
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

    @property
    def name(self) -> str:
        return str(self.params.get("program_name", f"JOB_{self.gear_id}"))


@dataclass(frozen=True)
class Program:
    program_id: int
    job_id: int
    name: str
    lines: list[str]
    gear_class: str
    template_version: int
    template_hash: str
    path: str | None = None
    trace: list | None = None        # engine.templates.trace: why each row emitted or not
    row_ids: list[int] | None = None  # the template row of each line

    @property
    def text(self) -> str:
        return "\n".join(self.lines) + "\n"
