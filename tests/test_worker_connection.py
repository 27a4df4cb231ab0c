"""The connection `conn` lends test after test (tests/helpers/worker_connection.py): nothing one
test does to it reaches the next, neither its rows nor its session's state."""
from __future__ import annotations

from helpers.worker_connection import WorkerConnection
from psycopg.rows import dict_row

SESSION_STATE = """SELECT current_user = session_user, current_setting('search_path'),
    (SELECT count(*) FROM pg_locks WHERE locktype = 'advisory' AND pid = pg_backend_pid()),
    (SELECT count(*) FROM pg_listening_channels()), (SELECT count(*) FROM pg_prepared_statements),
    (SELECT count(*) FROM pg_class WHERE relpersistence = 't'), (SELECT count(*) FROM pg_cursors),
    (SELECT count(*) FROM gear WHERE quantity = 987654)"""


def test_a_test_leaves_the_next_neither_rows_nor_session_state(fresh_database_url):
    lender = WorkerConnection(fresh_database_url)   # a private copy: the COMMIT below is this test's own
    with lender.lent() as first:
        before = first.execute(SESSION_STATE).fetchone()
        first.execute("UPDATE gear SET quantity = 987654")
        first.execute("CREATE TEMP TABLE scratch (x int)")
        first.execute("SET ROLE engine_reader")
    with lender.lent() as second:
        assert second.execute(SESSION_STATE).fetchone() == before
        second.execute("COMMIT")   # a test ending the fixture's transaction: what follows outlives a rollback
        second.execute("CREATE TEMP TABLE scratch (x int)")
        second.execute("SET ROLE engine_runner")
        second.execute("SET search_path = pg_catalog")
        second.execute("SELECT pg_advisory_lock(28)")
        second.execute("LISTEN issue_28")
        second.execute("PREPARE twice AS SELECT 2")
        second.execute("DECLARE kept CURSOR WITH HOLD FOR SELECT 1")
        second.execute("COMMIT")   # all of it is the session's now, beyond the fixture's rollback
    with lender.lent() as third:
        assert third is first
        assert third.execute(SESSION_STATE).fetchone() == before == (True, before[1], 0, 0, 0, 0, 0, 0)
    lender.close()


def test_a_connection_closed_broken_or_changed_by_a_test_is_not_lent_again(database_url):
    lender = WorkerConnection(database_url)
    with lender.lent() as first:
        first.row_factory = dict_row
    with lender.lent() as second:
        assert second is not first and first.closed
        assert second.execute("SELECT 1").fetchone() == (1,)
    try:
        with lender.lent() as third:
            third.close()
    except Exception:   # noqa: BLE001 — psycopg may refuse to roll back on a closed connection
        pass
    with lender.lent() as fourth:
        assert fourth is not third and not fourth.closed
    lender.close()
