"""What a command left behind, read back as a user would: the jobs stored, and a refusal that
must be one line on stderr with exit code 1 (the house rule for user errors)."""
from __future__ import annotations

import psycopg


def job_count(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM job").fetchone()[0]


def one_line_refusal(result) -> str:
    assert result.exit_code == 1, result.output
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    return result.stderr.strip()
