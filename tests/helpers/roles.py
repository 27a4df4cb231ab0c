"""Acting as one of the engine's roles inside a test's transaction (the test user is a
superuser; SET ROLE drops to the role's privileges)."""
from __future__ import annotations

import uuid
from contextlib import contextmanager
from dataclasses import dataclass

import psycopg
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo
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


@dataclass(frozen=True)
class Login:
    """A login person of the cluster, member of an engine_* role, made for one test."""
    name: str
    password: str

    def url(self, database_url: str) -> str:
        return make_conninfo(**{**conninfo_to_dict(database_url), "user": self.name, "password": self.password})


@contextmanager
def logins(server_url):
    """create("engine_editor") -> a new Login in that role; every one is dropped afterwards."""
    made = []

    def create(role: str) -> Login:
        login = Login(f"records_{uuid.uuid4().hex[:12]}", uuid.uuid4().hex)
        with psycopg.connect(server_url, autocommit=True) as admin:
            admin.execute(sql.SQL("CREATE ROLE {} LOGIN PASSWORD {} IN ROLE {}").format(
                sql.Identifier(login.name), sql.Literal(login.password), sql.Identifier(role)))
        made.append(login)
        return login
    try:
        yield create
    finally:
        with psycopg.connect(server_url, autocommit=True) as admin:
            for login in made:
                admin.execute(sql.SQL("DROP ROLE IF EXISTS {}").format(sql.Identifier(login.name)))
