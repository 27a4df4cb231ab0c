"""`engine demo`: the whole way from an empty database to a program, on the embedded PostgreSQL.

The demo loads the sample gears, hobs and cases, so it never runs on a shop's database (issue
16): a DATABASE_URL or --database-url is ignored, never written to; and on the embedded server it
uses a database of its own, `engine_demo`, because the embedded server's `engine` database is a
shop's database too when it runs without a URL. A shop that wants the samples in its own
database says so: `engine seed --samples`."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..db.embedded import embedded_data_dir, embedded_url
from ..db.seed import SeedReport

DEMO_DATABASE = "engine_demo"


@dataclass(frozen=True)
class DemoResult:
    data_dir: Path          # where the embedded server keeps its data (database engine_demo)
    applied: int            # migrations applied by this run
    report: SeedReport
    program: object         # engine.programs.instantiate's Program


def run_demo(gear_id: int = 42) -> DemoResult:
    """Migrate and seed (samples included) the embedded server's database, instantiate one gear."""
    from ..db.connection import connect
    from ..db.migrate import migrate
    from ..db.seed import seed
    from .instantiate import instantiate_gear

    with connect(embedded_url(DEMO_DATABASE)) as conn:
        applied = migrate(conn)
        report = seed(conn, samples=True)
        program = instantiate_gear(conn, gear_id)
    return DemoResult(embedded_data_dir(), len(applied), report, program)
