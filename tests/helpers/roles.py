"""Acting as one of the engine's roles inside a test's transaction (the test user is a
superuser; SET ROLE drops to the role's privileges)."""
from __future__ import annotations

from contextlib import contextmanager

from psycopg import sql
from psycopg.pq import TransactionStatus


@contextmanager
def as_role(conn, role):
    """Act as `role` until the block ends (a failed transaction keeps the role until rollback)."""
    conn.execute(sql.SQL("SET ROLE {}").format(sql.Identifier(role)))
    try:
        yield
    finally:
        if conn.info.transaction_status != TransactionStatus.INERROR:
            conn.execute("RESET ROLE")
