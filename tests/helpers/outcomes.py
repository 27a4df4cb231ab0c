"""What a command said and left behind, read back as a user would: its JSON when it succeeded,
a refusal in one line on stderr with exit code 1 (the house rule for user errors), the jobs and
programs stored."""
from __future__ import annotations

import json

import psycopg


def job_count(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM job").fetchone()[0]


def one_line_refusal(result) -> str:
    assert result.exit_code == 1, result.output
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    return result.stderr.strip()


def one_line_error(result) -> bool:
    return result.exit_code == 1 and result.stderr.startswith("error: ") and result.stderr.count("\n") == 1


def made(result) -> dict:
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def counts(url) -> tuple[int, int]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()
