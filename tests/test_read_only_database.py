"""The shared database of the tests that only read (read_only_database_url, read_only_run in
tests/conftest.py, issue 28) refuses every write: a test put on it by mistake fails instead of
changing what the next test of its worker reads, and a command that writes where it should not
ends in exit 2, which the exit code a refusal test asserts (1) does not match (CONTRIBUTING.md)."""
from __future__ import annotations

import psycopg
import pytest


def test_a_write_on_the_shared_database_is_refused_by_the_server(read_only_database_url):
    with psycopg.connect(read_only_database_url) as conn:
        with pytest.raises(psycopg.errors.ReadOnlySqlTransaction):
            conn.execute("DELETE FROM gear WHERE id = 42")


def test_a_command_that_writes_on_it_ends_in_exit_2_and_stores_nothing(read_only_run):
    result = read_only_run("gears", "delete", 42, "--yes")
    assert result.exit_code == 2, result.output
    assert "ReadOnlySqlTransaction" in result.stderr and "read-only transaction" in result.stderr
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear WHERE id = 42").fetchone() == (1,)
