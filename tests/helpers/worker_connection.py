"""One connection per worker to a test database, lent to test after test (the `conn` fixture).

A new connection costs the client 4-5 ms and the server a fresh backend whose first queries load
its catalog caches: server CPU taken from the suite's two workers (issue 28: 725 of the fast
subset's 2,958 connections were `conn`'s own). Each test runs inside a transaction rolled back at
its end (tests/conftest.py), which undoes its writes, its SET and SET ROLE and its temporary
tables; what a rollback keeps (session-level advisory locks, LISTEN, PREPAREd statements, cursors
WITH HOLD, sequences' currval, a SET made after a COMMIT the test sent itself) DISCARD ALL
removes before the next test. A connection the test closed, broke, left in a transaction or
changed on the client side (autocommit, isolation, row factory, …) is closed and a new one made.
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import psycopg
from psycopg.pq import TransactionStatus

DEAD_ROWS_BEFORE_VACUUM = 3000
TESTS_BETWEEN_VACUUM_CHECKS = 20   # the dead rows of 20 tests are far fewer than the threshold


def client_state(connection: psycopg.Connection) -> tuple:
    """What a test could change on the connection object itself, which DISCARD ALL does not reset.
    A loader or dumper registered on the connection (read_bounded_json's) replaces, copy on write,
    one of the tables of its adapters: their identities tell."""
    adapters = connection.adapters
    tables = (*adapters._loaders, *adapters._dumpers.values(), *adapters._dumpers_by_oid)
    return (connection.autocommit, connection.isolation_level, connection.read_only, connection.deferrable,
            connection.row_factory, connection.cursor_factory, connection.prepare_threshold,
            connection.prepared_max, tuple(connection._notice_handlers), tuple(connection._notify_handlers),
            tuple(map(id, tables)))


class WorkerConnection:
    """with lent() as connection: one test's connection to `url`, in a transaction rolled back at
    the end, after which the session is reset for the next test."""

    def __init__(self, url: str):
        self.url = url
        self.connection: psycopg.Connection | None = None
        self.state: tuple = ()
        self.tests = 0

    @contextmanager
    def lent(self) -> Iterator[psycopg.Connection]:
        connection = self.lend()
        try:
            with connection.transaction(force_rollback=True):
                yield connection
        finally:
            self.taken_back()

    def lend(self) -> psycopg.Connection:
        if self.connection is None:
            self.connection = psycopg.connect(self.url)
            self.state = client_state(self.connection)
        self.tests += 1
        return self.connection

    def taken_back(self) -> None:
        """Reset the session for the next test, or drop the connection if it cannot be trusted."""
        connection = self.connection
        if connection is None or not self._reusable(connection):
            self.close()
            return
        try:
            connection.autocommit = True
            connection.execute("DISCARD ALL")
            if self.tests % TESTS_BETWEEN_VACUUM_CHECKS == 0:
                vacuum_if_bloated(connection)
            connection.autocommit = False
        except psycopg.Error:
            self.close()
            raise

    def _reusable(self, connection: psycopg.Connection) -> bool:
        return (not connection.closed and not connection.broken
                and connection.info.transaction_status == TransactionStatus.IDLE
                and client_state(connection) == self.state)

    def close(self) -> None:
        if self.connection is not None:
            self.connection.close()
        self.connection = None


def vacuum_if_bloated(connection: psycopg.Connection) -> None:
    """Every rolled-back insert leaves a dead row in the session's database, and autovacuum does
    not keep up with a suite (on a shared server it is busy elsewhere): by the middle of the suite
    assembly held 17,000 dead rows beside its 488 live ones and reading template_view took 1.7 s
    instead of 0.02 s. VACUUM removes only rows no transaction can see."""
    dead = connection.execute("SELECT coalesce(sum(n_dead_tup), 0) FROM pg_stat_all_tables").fetchone()[0]
    if dead > DEAD_ROWS_BEFORE_VACUUM:
        connection.execute("VACUUM")
