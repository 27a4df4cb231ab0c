"""The test databases the fixtures hand out, made ahead and dropped behind by background threads.

A test that commits needs a private copy of the seeded database. Copying it (CREATE DATABASE …
TEMPLATE) costs the server about a quarter of a second, and dropping it more: DROP DATABASE waits
for a checkpoint, which on a server other sessions share flushes their dirty pages too (a second
and more). Done in the test's own setup and teardown that time adds up over hundreds of tests;
here two threads copy the next databases while the current test runs, and others drop the used
ones, several at once so that their checkpoints are shared.

Copies are made from a template nobody connects to, so a test holding a connection to the session's
database (`conn`) never stops the next copy. Every database made here commits asynchronously
(synchronous_commit = off, set on the database, so the engine's and the CLI's own connections get it
too): a commit is visible to every other session at once either way; only a crash of the server
itself could lose the last commits, and no test crashes the server or reads what survives one.
"""
from __future__ import annotations

import subprocess
import sys
import threading
import uuid
from pathlib import Path

import psycopg
from psycopg import sql

MAKERS = 2          # copies made at once: a run of quick CLI tests uses one every 0.1-0.3 s
DROPS_AT_ONCE = 8   # concurrent DROP DATABASEs share one checkpoint; few connections of a shared server


def create_database(admin, name: str, template: str | None = None, file_copy: bool = False) -> None:
    """CREATE DATABASE `name` (a copy of `template` if given), committing asynchronously. The
    server's default strategy (WAL_LOG since PostgreSQL 15) writes the copy through the WAL;
    `file_copy` (STRATEGY FILE_COPY, 15 and later) copies the files and costs two checkpoints
    instead of writing the 10 MB copy through the WAL (about 2 GB of WAL a fast run, every byte of
    it CRC'd and flushed): on the embedded test server (fsync off) it took the fast subset from
    61 s to 54 s, on this machine's local server (fsync on) from 68-71 s to 63-64 s (issue 28).
    The checkpoints flush what other sessions of a shared server have dirtied too."""
    query = sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name))
    if template:
        query = sql.SQL("CREATE DATABASE {} TEMPLATE {}").format(sql.Identifier(name), sql.Identifier(template))
    if template and file_copy:
        query = sql.SQL("{} STRATEGY FILE_COPY").format(query)
    admin.execute(query)
    admin.execute(sql.SQL("ALTER DATABASE {} SET synchronous_commit = off").format(sql.Identifier(name)))


def drop_database(server_url: str, name: str) -> None:
    """DROP DATABASE `name`, ending any connection a test left open to it."""
    with psycopg.connect(server_url, autocommit=True) as admin:
        drop_with(admin, name)


def drop_with(admin, name: str) -> None:
    """DROP DATABASE `name` over the autocommit connection `admin`, ending any connection to it."""
    admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(name)))


# Run by drop_later in a process of its own: drops the databases named on its command line.
DROPPER = """
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
sys.path.insert(0, sys.argv[1])
from helpers.database_pool import DROPS_AT_ONCE, drop_database
with ThreadPoolExecutor(max_workers=DROPS_AT_ONCE) as drops:
    list(drops.map(lambda name: drop_database(sys.argv[2], name), sys.argv[3:]))
"""


def drop_later(server_url: str, names: list[str]) -> None:
    """DROP DATABASE each of `names` in a detached process (its own session: it outlives pytest).
    Against the embedded server, which stops when the session ends and whose folder is deleted
    with everything in it, the dropper finds no server and ends: nothing is left either way."""
    subprocess.Popen([sys.executable, "-c", DROPPER, str(Path(__file__).resolve().parent.parent), server_url,
                      *names], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                     start_new_session=True)


class Kind:
    """Databases of one kind: copies of `template` (None: empty ones) named `prefix`_<random hex>,
    `ahead` of them kept ready."""

    def __init__(self, template: str | None, prefix: str, hex_digits: int, ahead: int):
        self.template, self.prefix, self.hex_digits, self.ahead = template, prefix, hex_digits, ahead
        self.ready: list[str] = []
        self.making = 0

    def new_name(self) -> str:
        return f"{self.prefix}_{uuid.uuid4().hex[:self.hex_digits]}"

    def short(self) -> bool:
        return len(self.ready) + self.making < self.ahead


class DatabasePool:
    """take(kind) → the name of a database made for one test; give_back(name) drops it later.
    close() stops the threads and drops every database still made here."""

    def __init__(self, server_url: str, file_copy: bool = False):
        self.server_url, self.file_copy = server_url, file_copy
        self.kinds: list[Kind] = []
        self.used: list[str] = []
        self.dropping: list[str] = []   # being dropped by the drop threads (dropped again at close: IF EXISTS)
        self.error: BaseException | None = None
        self.closing = False
        self.changed = threading.Condition()
        self.threads = [threading.Thread(target=self._guarded, args=(work,), daemon=True)
                        for work in (self._make_ahead,) * MAKERS + (self._drop_behind,) * DROPS_AT_ONCE]
        for thread in self.threads:
            thread.start()

    def kind(self, template: str | None, prefix: str, hex_digits: int = 6, ahead: int = 3) -> Kind:
        """A new kind of database; the maker starts copying `ahead` of them at the first take()."""
        return Kind(template, prefix, hex_digits, ahead)

    def take(self, kind: Kind) -> str:
        """A database of `kind` for one test, waiting for the maker if none is ready yet."""
        with self.changed:
            if kind not in self.kinds:
                self.kinds.append(kind)
                self.changed.notify_all()
            self.changed.wait_for(lambda: kind.ready or self.error or self.closing)
            self._raise_error()
            if not kind.ready:
                raise RuntimeError("the test database pool is closed")
            self.changed.notify_all()   # the kind is short now: the makers copy the next one
            return kind.ready.pop(0)

    def give_back(self, name: str) -> None:
        """The test is done with `name`: drop it in the background."""
        with self.changed:
            self.used.append(name)
            self.changed.notify_all()

    def close(self) -> None:
        """Stop making, then have what is still ready or used (every database made here) dropped by
        a process of its own, which the session does not wait for: each DROP DATABASE waits for a
        checkpoint, and at the end of a worker's session a dozen of them took 10-25 s on a busy
        server (issue 28), time in which no test ran."""
        with self.changed:
            self.closing = True
            self.changed.notify_all()
        for thread in self.threads[:MAKERS]:   # not the dropper: it may be waiting for a checkpoint
            thread.join()
        with self.changed:
            leftovers = self.used + self.dropping + [name for kind in self.kinds for name in kind.ready]
        if leftovers:
            drop_later(self.server_url, leftovers)
        self._raise_error()

    # --- the threads ------------------------------------------------------------------------------

    def _raise_error(self) -> None:
        if self.error is not None:
            raise RuntimeError(f"the test database pool failed: {self.error}") from self.error

    def _guarded(self, work) -> None:
        """Run `work`; a failure is kept and raised in the test that waits, not lost in a thread."""
        try:
            work()
        except BaseException as error:   # noqa: BLE001 — handed over to the main thread
            with self.changed:
                self.error = error
                self.changed.notify_all()

    def _make_ahead(self) -> None:
        with psycopg.connect(self.server_url, autocommit=True) as admin:
            while (kind := self._next_short_kind()) is not None:
                name = kind.new_name()
                create_database(admin, name, kind.template, self.file_copy)
                with self.changed:
                    kind.making -= 1
                    kind.ready.append(name)
                    self.changed.notify_all()

    def _next_short_kind(self) -> Kind | None:
        """The kind that most needs a database next (none ready first); None when closing."""
        with self.changed:
            self.changed.wait_for(lambda: self.closing or any(kind.short() for kind in self.kinds))
            if self.closing:
                return None
            kind = min((kind for kind in self.kinds if kind.short()), key=lambda kind: len(kind.ready) + kind.making)
            kind.making += 1
            return kind

    def _drop_behind(self) -> None:
        """One of DROPS_AT_ONCE daemon threads, each dropping over a connection of its own, made at
        its first drop and kept: a connection per DROP was a new server backend each time, 360 of
        the fast subset's 2,200 connections (issue 28). Daemon threads, because the interpreter
        joins a ThreadPoolExecutor's at exit: on the local server, where each DROP DATABASE waits
        for a checkpoint, a worker stayed 4-10 s after its last test for the drops in progress.
        What they leave undone close() hands to the detached dropper (DROP … IF EXISTS)."""
        admin = None
        try:
            while name := self._next_drop():
                admin = admin or psycopg.connect(self.server_url, autocommit=True)
                drop_with(admin, name)
                with self.changed:
                    self.dropping.remove(name)   # dropped: not handed to the dropper at close again
        finally:
            if admin is not None:
                admin.close()

    def _next_drop(self) -> str | None:
        """The used database given back first and not yet dropped; None when closing."""
        with self.changed:
            self.changed.wait_for(lambda: self.closing or self.used)
            if self.closing:
                return None
            name = self.used.pop(0)
            self.dropping.append(name)
            return name
