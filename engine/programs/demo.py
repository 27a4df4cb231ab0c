"""`engine demo`: the whole way from an empty database to a program, on the embedded PostgreSQL.

The demo loads the sample gears, hobs and cases, so it never runs on a shop's database (issue
16): a DATABASE_URL or --database-url is ignored, never written to. A shop that wants the
samples in its own database says so: `engine seed --samples`."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..db.embedded import embedded_data_dir, embedded_url
from ..db.seed import SeedReport


@dataclass(frozen=True)
class DemoResult:
    data_dir: Path          # where the embedded server keeps its data
    applied: int            # migrations applied by this run
    report: SeedReport
    program: object         # engine.programs.instantiate's Program


def run_demo(gear_id: int = 42) -> DemoResult:
    """Migrate and seed (samples included) the embedded server's database, instantiate one gear."""
    from ..db.connection import connect
    from ..db.migrate import migrate
    from ..db.seed import seed
    from .instantiate import instantiate_gear

    with connect(embedded_url()) as conn:
        applied = migrate(conn)
        report = seed(conn, samples=True)
        program = instantiate_gear(conn, gear_id)
    return DemoResult(embedded_data_dir(), len(applied), report, program)
