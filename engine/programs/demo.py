"""`engine demo`: the whole way from an empty database to a program, on the embedded PostgreSQL.

The demo loads the sample gears, hobs and cases, so it never runs on a shop's database (issue
16): a DATABASE_URL or --database-url is ignored, never written to; and on the embedded server it
uses a database of its own, `engine_demo`, because the embedded server's `engine` database is a
shop's database too when it runs without a URL. A shop that wants the samples in its own
database says so: `engine seed --samples`.

`engine demo --turning` makes a turning job of the project's sample drawing instead (issue 17:
no real drawing carries operation layers, so users need one to copy): the command line hands
run_demo the importer that makes it (importers.sample, design notes §3), which stands above this
layer."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import msgspec

from ..db.embedded import embedded_data_dir, embedded_url
from ..library.seed import SeedReport

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .records import Program

DEMO_DATABASE = "engine_demo"


class Sample(Protocol):
    """What a sample importer returns (importers.sample.SampleJob): the drawing, its job, the program."""
    @property
    def drawing(self) -> Path: ...
    @property
    def job(self) -> Any: ...
    @property
    def program(self) -> Program: ...


class DemoResult(msgspec.Struct, frozen=True):
    data_dir: Path          # where the embedded server keeps its data (database engine_demo)
    applied: int            # migrations applied by this run
    report: SeedReport
    program: Program
    sample: Sample | None = None   # with --turning: the job the program was made for


def run_demo(gear_id: int = 42, sample_job: Callable[[Connection], Sample] | None = None) -> DemoResult:
    """Migrate and seed (samples included) the embedded server's database, then instantiate one
    gear, or with `sample_job` (importers.sample.sample_turning_job) the sample drawing's job."""
    from ..db.connection import connect
    from ..db.migrate import migrate
    from ..library.seed import seed
    from .instantiate import instantiate_gear

    with connect(embedded_url(DEMO_DATABASE)) as conn:
        applied = migrate(conn)
        report = seed(conn, samples=True)
        sample = sample_job(conn) if sample_job else None
        program = sample.program if sample else instantiate_gear(conn, gear_id)
    return DemoResult(embedded_data_dir(), len(applied), report, program, sample)


def operations_line(job) -> str:
    """The job's operations as one line: number, kind, tool, spindle, feed (none for a thread)."""
    return ", ".join(f"{op['operation']} {op['kind']} T{op['tool']} S{op['spindle_rpm']:g}"
                     + (f" F{op['feed']:g}" if op["feed"] is not None else "") for op in job.operations)
