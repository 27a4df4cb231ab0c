"""Where the database is: --database-url, DATABASE_URL, libpq PG* variables, or the embedded server."""
from __future__ import annotations

import os
import re
from typing import TYPE_CHECKING, Any

from ..errors import EngineError

if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import TypeAlias

    import psycopg
    from psycopg import Cursor
    from psycopg.rows import TupleRow

    # every connection the engine opens reads rows as tuples (psycopg's default row factory)
    Connection: TypeAlias = psycopg.Connection[TupleRow]

LIBPQ_KEYWORDS = {"PGHOST": "host", "PGHOSTADDR": "hostaddr", "PGPORT": "port", "PGDATABASE": "dbname",
                  "PGUSER": "user", "PGSERVICE": "service"}   # each names a server of its own
LIBPQ_VARIABLES = tuple(LIBPQ_KEYWORDS)


def resolve_url(database_url: str | None = None) -> str:
    """The connection string to use, in the order of design notes §9."""
    if database_url:
        return database_url
    if os.environ.get("DATABASE_URL"):
        return os.environ["DATABASE_URL"]
    if any(os.environ.get(name) for name in LIBPQ_VARIABLES):
        return ""  # libpq reads the PG* variables itself
    from .embedded import embedded_url  # the server of its own only when none is named (issue 28: start-up)

    return embedded_url()


def url_in_use(database_url: str | None = None) -> tuple[str, str]:
    """`engine db url`: the connection string in use and where it came from (the embedded
    server is started if it is the one). For libpq's PG* variables, the conninfo they make."""
    url = resolve_url(database_url)
    if url and (database_url or os.environ.get("DATABASE_URL")):
        return url, "DATABASE_URL" if url == os.environ.get("DATABASE_URL") else "--database-url"
    if not url:
        return _libpq_conninfo(), "the PG* variables"
    from .embedded import embedded_data_dir

    return url, f"the embedded PostgreSQL, data in {embedded_data_dir()}"


def _libpq_conninfo() -> str:
    from psycopg.conninfo import make_conninfo

    return make_conninfo(**{keyword: os.environ[name] for name, keyword in LIBPQ_KEYWORDS.items()
                            if os.environ.get(name)})


def psql_command(database_url: str | None, args: Sequence[str] = ()) -> list[str]:
    """`engine db psql`: the psql command line on the database in use; refused, with the
    command to run once a PostgreSQL client is installed, if no psql is found."""
    import shlex

    from .embedded import bin_dir, find_psql

    url = url_in_use(database_url)[0]
    psql = find_psql()
    if psql is None:
        raise EngineError(f"no psql found (neither in {bin_dir()} nor on PATH); install the PostgreSQL "
                          f"client and run: {shlex.join(['psql', '--dbname', url, *args])}")
    return [psql, "--dbname", url, *args]


def connect(database_url: str | None = None, **kwargs: Any) -> Connection:
    """A psycopg connection to the resolved database; its JSON numbers are read bounded
    (engine.db.json_numbers)."""
    import psycopg

    from .json_numbers import read_bounded_json

    url = resolve_url(database_url)
    try:
        conn = psycopg.connect(url, **kwargs)
    except (psycopg.OperationalError, psycopg.ProgrammingError) as error:   # unreachable, or a malformed URL
        where = shown_url(url) if url else "the server named by the PG* variables"
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise EngineError(f"cannot connect to {where}: {without_password(first_line, url)}") from error
    read_bounded_json(conn)
    return conn


def shown_url(url: str) -> str:
    """The connection string as an error may show it: as given, or, if it holds a password, with
    the password written ****. An error is printed on a shop's screen, logged and pasted into
    tickets (the adversary of issue 32 found `engine serve` printing postgresql://user:PASSWORD@…)."""
    from psycopg import ProgrammingError
    from psycopg.conninfo import conninfo_to_dict, make_conninfo

    try:
        if "password" not in conninfo_to_dict(url):
            return url
        return make_conninfo(url, password="****")
    except ProgrammingError:   # not a connection string libpq reads: nothing of it is shown
        return "the database URL given (libpq cannot read it)"


def scalar(cursor: Cursor[TupleRow]) -> Any:
    """The first column of the one row a query always returns (a count, EXISTS, a function's value)."""
    row = cursor.fetchone()
    assert row is not None, "a query that always returns a row returned none"
    return row[0]


# Where a connection string holds a password: a URI's user info, its query, a keyword's value.
PASSWORDS = (re.compile(r"^(postgres(?:ql)?://[^:@/?#]*:)([^@/?#]*)(?=@)"), re.compile(r"([?&]password=)([^&#]*)"),
             re.compile(r"(\bpassword\s*=\s*)('(?:[^'\\]|\\.)*'|[^\s']\S*)"))


def without_password(text: str, url: str) -> str:
    """`text`, a message about `url`, with the passwords `url` holds as ***: a head office's URL,
    given to `engine plant subscribe`, holds one, and libpq quotes a malformed token of it in its
    message (shown_url hides it in the URL itself, not in what the server or libpq says)."""
    from urllib.parse import unquote

    secrets = {found.group(2) for pattern in PASSWORDS for found in pattern.finditer(url) if found.group(2)}
    secrets |= {unquote(secret) for secret in secrets} | {secret.strip("'") for secret in secrets}
    for secret in sorted(filter(None, secrets), key=len, reverse=True):
        text = text.replace(secret, "***")
    return text
