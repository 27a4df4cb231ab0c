"""Numbers in the JSON the engine reads from the database (job parameters, module parameters,
cutting data, traces), bounded as they are read. A runner may write any jsonb in SQL; a whole
number of thousands of digits made Python's int() fail (it refuses more than 4300 digits) and
one of hundreds made every float computation with it overflow. So a whole number of more than
MAX_WHOLE_DIGITS digits (more than a double holds exactly, and more than any parameter of a
gear, hob or job needs) or a decimal beyond a double's range is refused in one line, naming
where to look, before any code computes with it."""
from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

from ..errors import EngineError

if TYPE_CHECKING:
    import psycopg

MAX_WHOLE_DIGITS = 15
SHOWN_DIGITS = 12
WHOLE_RUN = "'[^0-9.][0-9]{16,}[^0-9.]'"   # a whole number of 16 digits or more in a jsonb's text
FIND_JOBS = f"SELECT id FROM job WHERE params::text ~ {WHOLE_RUN} OR module_params::text ~ {WHOLE_RUN}"


def bounded_loads(text: str | bytes) -> Any:
    """json.loads, refusing numbers no parameter can be (EngineError)."""
    return json.loads(text, parse_int=_whole, parse_float=_decimal)


def read_bounded_json(conn: psycopg.Connection[Any]) -> None:
    """Every json/jsonb value this connection reads is read with bounded_loads."""
    from psycopg.types.json import set_json_loads

    set_json_loads(bounded_loads, conn)


def _whole(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_WHOLE_DIGITS:
        raise EngineError(f"a number stored in the database has {digits} digits ({text[:SHOWN_DIGITS]}…), more "
                          f"than the {MAX_WHOLE_DIGITS} any parameter may have; correct it in SQL "
                          f"(`{FIND_JOBS}` finds the jobs that hold one)")
    return int(text)


def _decimal(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise EngineError(f"a number stored in the database ({text[:SHOWN_DIGITS]}…) is too large for any "
                          f"parameter; correct it in SQL (`{FIND_JOBS}` finds the jobs that hold one)")
    return value
