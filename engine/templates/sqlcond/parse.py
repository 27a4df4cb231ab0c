"""SQL text -> sqlglot tree (PostgreSQL dialect), with one-line error messages."""

from __future__ import annotations

import sqlglot
from sqlglot import exp
from sqlglot.errors import ParseError, SqlglotError, TokenError
from sqlglot.tokens import TokenType

from ...errors import EngineError

NOT_PARSED = "not a Python or SQL expression"


def short(text, limit=60):
    """`text` on one line, cut to `limit` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def render(node):
    """A sqlglot node as SQL text for a message."""
    try:
        return short(node.sql(dialect="postgres"))
    except Exception:  # noqa: BLE001 - only used for messages
        return type(node).__name__


def _column_of(text, offset):
    return offset - text.rfind("\n", 0, offset)


def _parse_error_message(error):
    details = error.errors[0] if getattr(error, "errors", None) else None
    if not details:
        if str(error).startswith("No expression was parsed"):
            return "empty condition"
        return short(str(error).splitlines()[0] if str(error) else type(error).__name__, 100)
    token = short(details.get("highlight") or "", 30)
    column = max(1, (details.get("col") or 1) - len(details.get("highlight") or "") + 1)
    line = details.get("line") or 1
    where = f"at column {column}" if line <= 1 else f"at line {line} column {column}"
    description = details.get("description") or ""
    if description.startswith("Invalid expression / Unexpected token"):
        return f"unexpected token {token!r} {where}"
    if description.startswith("Required keyword"):
        return f"incomplete expression near {token!r} {where}"
    if description.startswith("Expecting"):
        return f"{description.lower()} near {token!r} {where}"
    return f"{short(description, 80)} near {token!r} {where}"


def parse(text):
    """Parse one SQL condition; a second statement (';') is rejected."""
    dialect = sqlglot.Dialect.get_or_raise("postgres")
    try:
        tokens = dialect.tokenize(text)
    except TokenError as error:
        raise EngineError(f"{NOT_PARSED}: cannot split into SQL tokens ({short(error, 80)})") from None
    for token in tokens:
        if token.token_type == TokenType.SEMICOLON:
            column = _column_of(text, token.start)
            raise EngineError(f"{NOT_PARSED}: ';' at column {column}; a condition is a single expression")
    try:
        return sqlglot.parse_one(text, read=dialect, into=exp.Condition)
    except ParseError as error:
        raise EngineError(f"{NOT_PARSED}: {_parse_error_message(error)}") from None
    except SqlglotError as error:
        raise EngineError(f"{NOT_PARSED}: {short(str(error), 80)}") from None
    except Exception as error:  # noqa: BLE001 - sqlglot fails inside on some texts (issue 26:
        # `(floor()[:]` raised AttributeError typing floor's missing argument): the editor's text
        # is still what cannot be read, refused in one line, never a crash (exit 2)
        raise EngineError(f"{NOT_PARSED}: the SQL parser cannot read it ({type(error).__name__}); "
                          "check its brackets and each function's arguments") from None


def reject_subqueries(tree):
    for node in tree.walk():
        if isinstance(node, (exp.Query, exp.Subquery, exp.Exists)):
            raise EngineError(f"subquery not allowed in condition: {render(node)}")
