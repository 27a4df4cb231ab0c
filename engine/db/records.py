"""Database rows read as frozen records (a msgspec.Struct per table): the column list a query selects,
taken from the record's fields, and a row read with its numeric columns as checked floats."""
from __future__ import annotations

from collections.abc import Collection, Sequence
from decimal import Decimal
from typing import Any, TypeVar

import msgspec

from ..errors import EngineError
from ..quantities import MAX_MAGNITUDE  # the CSV readers refuse larger numbers; so do the records

Record = TypeVar("Record", bound=msgspec.Struct)   # Gear, Hob, Machine, ...


def columns(record_type: type[msgspec.Struct], exclude: Collection[str] = frozenset()) -> str:
    """`a, b, c`: the record's fields as the columns of a static SELECT (never user input)."""
    return ", ".join(name for name in record_type.__struct_fields__ if name not in exclude)


def as_float(record_type: type[Record], row: Sequence[Any], kind: str = "record") -> Record:
    """numeric columns arrive as Decimal; models compute in float, so each must be a finite
    float of a plausible size (a record edited in SQL is read as strictly as a file)."""
    values = [float(v) if isinstance(v, Decimal) else v for v in row]
    for name, value, stored in zip(record_type.__struct_fields__, values, row):
        if isinstance(value, float) and not abs(value) <= MAX_MAGNITUDE:   # NaN fails too
            raise EngineError(f"{kind} {row[0]}: {name} {stored} is not a number "
                              f"of at most {MAX_MAGNITUDE:g} in size; correct it (in the database or the CSV file)")
    return record_type(*values)
