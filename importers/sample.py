"""`engine demo --turning`: the project's sample drawing made a turning job and its program (issue
17: no real drawing carries operation layers, so users need one to copy). It imports the drawing
on the default lathe, as `engine import-dxf` does, and instantiates the job, as `engine
instantiate --job` does, on whatever connection it is given."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from engine.paths import SAMPLE_DRAWING
from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions

from .dxf import ImportReport, import_dxf

if TYPE_CHECKING:
    from engine.db.connection import Connection
    from engine.programs.records import Program

# mm: the blank the sample drawing's roughing starts from (seed_templates/drawings/README.md);
# the convention has no place for it in the drawing, so it is given as `--stock-diameter` would be.
SAMPLE_STOCK_DIAMETER = 44.0


@dataclass(frozen=True)
class SampleJob:
    drawing: Path           # the sample drawing, to copy as the start of one's own
    job: ImportReport
    program: Program


def sample_turning_job(conn: Connection, drawing: Path = SAMPLE_DRAWING) -> SampleJob:
    """Import the sample drawing as a turning job on the default lathe (from the Ø44 blank) and
    store its program, as `engine import-dxf` and `engine instantiate --job` do."""
    job = import_dxf(conn, drawing, options=ProfileOptions(stock_diameter=SAMPLE_STOCK_DIAMETER))
    return SampleJob(drawing, job, instantiate_job(conn, job.job_id))
