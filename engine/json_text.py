"""The JSON text the engine prints (`--json` of every command) and the web view answers
(`engine serve`, `Accept: application/json`): one object on one line, written the same way by
both, so a page's JSON is the command's, value for value (a time as `str` writes it, a numeric
column's value as the number of its digits); and the text of one value in their tables (cell)."""
from __future__ import annotations

import json
import re
from datetime import datetime
from decimal import Decimal
from typing import Any


def json_line(payload: Any) -> str:
    """The payload as one line of JSON, anything JSON has no type for as its str() (design notes §9)."""
    return json.dumps(payload, default=str)


# A Decimal's digits stand in a string between NULs (no text of the database holds NUL) until the
# JSON is written, then replace that string: json writes no Decimal, and a float would round it.
DECIMAL_MARK = "\0decimal\0"
MARKED = re.compile(r'"\\u0000decimal\\u0000(-?[0-9.]+)"')


def exact_json(payload: Any) -> str:
    """The payload as one line of JSON, a Decimal (a numeric column's value) as the number of its
    digits as stored (2.50 stays 2.50; NaN and infinities, which JSON has no number for, as text)."""
    return MARKED.sub(r"\1", json_line(_marked(payload)))


def _marked(value: Any) -> Any:
    if isinstance(value, dict):
        return {key: _marked(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_marked(item) for item in value]
    if isinstance(value, Decimal) and value.is_finite():
        return DECIMAL_MARK + format(value, "f")
    return value


def cell(value: Any) -> str:
    """A value as the CLI's tables and the web view's show it: '-' for none, 2.0 as 2, a time to the minute."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, datetime):
        return value.isoformat(sep=" ", timespec="minutes")
    return str(value)
