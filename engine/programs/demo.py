"""`engine demo`: the whole way from an empty database to a program, on the embedded PostgreSQL.

The demo loads the sample gears, hobs and cases, so it never runs on a shop's database (issue
16): a DATABASE_URL or --database-url is ignored, never written to; and on the embedded server it
uses a database of its own, `engine_demo`, because the embedded server's `engine` database is a
shop's database too when it runs without a URL. A shop that wants the samples in its own
database says so: `engine seed --samples`.

`engine demo --turning` makes a turning job of the project's sample drawing instead (issue 17:
no real drawing carries operation layers, so users need one to copy): sample_turning_job
imports it on the default lathe and instantiates it, on whatever connection it is given."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..db.embedded import embedded_data_dir, embedded_url
from ..library.seed import SeedReport
from ..paths import SAMPLE_DRAWING

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .dxf_import import ImportReport
    from .records import Program

DEMO_DATABASE = "engine_demo"
# mm: the blank the sample drawing's roughing starts from (seed_templates/drawings/README.md);
# the convention has no place for it in the drawing, so it is given as `--stock-diameter` would be.
SAMPLE_STOCK_DIAMETER = 44.0


@dataclass(frozen=True)
class SampleJob:
    drawing: Path           # the sample drawing, to copy as the start of one's own
    job: ImportReport
    program: Program


@dataclass(frozen=True)
class DemoResult:
    data_dir: Path          # where the embedded server keeps its data (database engine_demo)
    applied: int            # migrations applied by this run
    report: SeedReport
    program: Program
    sample: SampleJob | None = None   # with --turning: the job the program was made for


def run_demo(gear_id: int = 42, turning: bool = False) -> DemoResult:
    """Migrate and seed (samples included) the embedded server's database, then instantiate one
    gear, or with `turning` the sample drawing's turning job."""
    from ..db.connection import connect
    from ..db.migrate import migrate
    from ..library.seed import seed
    from .instantiate import instantiate_gear

    with connect(embedded_url(DEMO_DATABASE)) as conn:
        applied = migrate(conn)
        report = seed(conn, samples=True)
        sample = sample_turning_job(conn) if turning else None
        program = sample.program if sample else instantiate_gear(conn, gear_id)
    return DemoResult(embedded_data_dir(), len(applied), report, program, sample)


def sample_turning_job(conn: Connection, drawing: Path = SAMPLE_DRAWING) -> SampleJob:
    """Import the sample drawing as a turning job on the default lathe (from the Ø44 blank) and
    store its program, as `engine import-dxf` and `engine instantiate --job` do."""
    from ..turning.job_params import ProfileOptions
    from .dxf_import import import_dxf
    from .remake import instantiate_job

    job = import_dxf(conn, drawing, options=ProfileOptions(stock_diameter=SAMPLE_STOCK_DIAMETER))
    return SampleJob(drawing, job, instantiate_job(conn, job.job_id))


def operations_line(job) -> str:
    """The job's operations as one line: number, kind, tool, spindle, feed (none for a thread)."""
    return ", ".join(f"{op['operation']} {op['kind']} T{op['tool']} S{op['spindle_rpm']:g}"
                     + (f" F{op['feed']:g}" if op["feed"] is not None else "") for op in job.operations)
