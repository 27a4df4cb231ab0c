"""Shared by the benchmarks: the server's admin URL, the smoke mode, a private database that is
always dropped, medians and the PASS/MISS wording. Benchmarks report; they never fail on a target.

`--smoke` (bench/smoke.py, .ci/run) runs a benchmark at small sizes with one repetition, to show
that it still runs: its figures are printed but not judged, since sizes that small say nothing
about the targets. Options given on the command line win over the smoke sizes."""
from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import uuid

DEFAULT_ADMIN_URL = "postgresql://postgres@127.0.0.1:5432/postgres"
NOT_JUDGED = "not judged (--smoke)"
_smoke = False   # set by parse_arguments: the run is a smoke run, its verdicts are not given


def add_database_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--database-url", default=os.environ.get("DATABASE_URL") or DEFAULT_ADMIN_URL,
        help="admin URL of the PostgreSQL server; the benchmark creates (and drops) its own database "
             "there (default: DATABASE_URL, else %(default)s)")


def parse_arguments(parser: argparse.ArgumentParser, argv, smoke: dict) -> argparse.Namespace:
    """The parsed command line; with --smoke, `smoke` (option dest -> value) replaces the defaults."""
    global _smoke
    sizes = ", ".join(_option(name, value) for name, value in smoke.items())
    parser.add_argument("--smoke", action="store_true",
                        help=f"check that the benchmark runs: {sizes or 'as by default'}; figures not judged")
    args = parser.parse_args(argv)
    if args.smoke:
        parser.set_defaults(**smoke)
        args = parser.parse_args(argv)
    _smoke = args.smoke
    return args


def _option(name: str, value) -> str:
    flag = "--" + name.replace("_", "-")
    return flag if value is True else f"{flag} {value}"


def url_of(server_url: str, database: str) -> str:
    from psycopg.conninfo import conninfo_to_dict, make_conninfo

    params = conninfo_to_dict(server_url)
    params["dbname"] = database
    return make_conninfo(**params)


@contextlib.contextmanager
def bench_database(server_url: str, prefix: str, *, seeded: bool = True):
    """Create a uniquely named database (migrated and seeded), yield its URL, drop it
    at the end even when the benchmark fails."""
    import psycopg
    from psycopg import sql

    name = f"{prefix}_{uuid.uuid4().hex[:10]}"
    with psycopg.connect(server_url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
    try:
        url = url_of(server_url, name)
        if seeded:
            from engine.db.migrate import migrate
            from engine.library.seed import seed

            with psycopg.connect(url) as conn:
                migrate(conn)
                seed(conn)
                conn.commit()
        yield url
    finally:
        with psycopg.connect(server_url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(name)))


def delete_programs(conn) -> None:
    """Empty the program table of a benchmark's own database between runs. Programs are records:
    a trigger refuses every DELETE (migration 0010); only the owner of this throwaway database
    can switch it off, and does so for this one statement."""
    with conn.transaction():
        conn.execute("ALTER TABLE program DISABLE TRIGGER program_is_a_record")
        conn.execute("DELETE FROM program")
        conn.execute("ALTER TABLE program ENABLE TRIGGER program_is_a_record")


def median(values) -> float:
    return statistics.median(values)


def verdict(ok: bool) -> str:
    if _smoke:
        return NOT_JUDGED
    return "PASS" if ok else "MISS"
