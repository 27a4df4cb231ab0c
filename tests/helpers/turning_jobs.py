"""A fixture plugin (tests/conftest.py loads it): `seed_job`, the seed drawing's turning job in the
test's rolled-back transaction, and the check that a job edited in SQL is refused in one line."""
from __future__ import annotations

import pytest

from engine.errors import EngineError
from engine.programs.remake import instantiate_job
from helpers.drawings import seed_drawing
from importers.dxf import import_dxf


@pytest.fixture
def seed_job(conn, tmp_path) -> int:
    seed_drawing(tmp_path / "part.dxf")
    return import_dxf(conn, tmp_path / "part.dxf").job_id


def program_count(conn) -> int:
    return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def refused_after(conn, job_id: int, set_sql: str, message: str) -> None:
    """The job edited by `set_sql` (an UPDATE's SET) is refused with `message`; nothing stored."""
    conn.execute(f"UPDATE job SET {set_sql} WHERE id = %s", (job_id,))
    before = program_count(conn)
    with pytest.raises(EngineError, match=message) as refused:
        instantiate_job(conn, job_id)
    assert "\n" not in str(refused.value)
    assert program_count(conn) == before
