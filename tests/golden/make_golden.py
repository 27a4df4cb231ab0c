"""Write the golden programs (tests/helpers/golden_cases.py): a seeded database is made on the server
of DATABASE_URL (admin URL; default the local server), every case is instantiated and rolled
back, and its text written here. Run it only when programs are meant to change, and read the
diff before committing it.

    python tests/golden/make_golden.py [--database-url postgresql://postgres@127.0.0.1:5432/postgres]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import uuid
from functools import partial
from pathlib import Path

import psycopg
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # tests/: golden_cases and its makers

from helpers.golden_cases import (  # noqa: E402
    FANUC_MACHINE,
    fanuc_hobbing_file,
    hobbing_cases,
    hobbing_file,
    hobbing_text,
    turning_cases,
    turning_file,
    turning_text,
)


def seeded_database(admin_url: str) -> tuple[str, str]:
    from engine.db.migrate import migrate
    from engine.library.seed import seed

    name = f"engine_golden_{uuid.uuid4().hex[:10]}"
    with psycopg.connect(admin_url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
    url = make_conninfo(**{**conninfo_to_dict(admin_url), "dbname": name})
    with psycopg.connect(url) as conn:
        migrate(conn)
        seed(conn)
    return name, url


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def rolled_back(url: str, make):
    with psycopg.connect(url) as conn, conn.transaction(force_rollback=True):
        return make(conn)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--database-url", default=os.environ.get("DATABASE_URL")
                        or "postgresql://postgres@127.0.0.1:5432/postgres")
    args = parser.parse_args()
    name, url = seeded_database(args.database_url)
    try:
        for gear_id, choice_set in hobbing_cases():
            write(hobbing_file(gear_id, choice_set),
                  rolled_back(url, partial(hobbing_text, gear_id=gear_id, choice_set=choice_set)))
            write(fanuc_hobbing_file(gear_id, choice_set),
                  rolled_back(url, partial(hobbing_text, gear_id=gear_id, choice_set=choice_set,
                                           machine=FANUC_MACHINE)))
        with tempfile.TemporaryDirectory() as folder:
            for case, lathe in turning_cases():
                write(turning_file(case, lathe),
                      rolled_back(url, partial(turning_text, folder=Path(folder), name=case, lathe=lathe)))
    finally:
        with psycopg.connect(args.database_url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(name)))
    print(f"wrote {len(hobbing_cases())} hobbing (each on the 840D and the Fanuc hobber) and "
          f"{len(turning_cases())} turning golden files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
