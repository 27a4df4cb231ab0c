"""The trace of a program: for every row of the template version, whether `s` ran or `p_calc`
skipped the row, whether `o` was emitted or `p_emit` suppressed it, the value of each
condition, the values computed, and the inputs each expression read (name → where the value
came from: the job, a module's parameters, the row that computed it; and so its value).

As stored in `program.trace`, compact: each input value once, under its origin, and one entry
per row in id order that names the origin of what it read:
    {"inputs": {"job": {"coolant": false, "z2": 19, ...}, "module cutmotion:2": {"cut_x": 51.5}},
     "rows": [{"row": 1400, "computed": {"coupling_z0": -1}, "read": {"s": {"z0": "job"}}},
              {"row": 1500, "emit": true, "read": {"o": {"coupling_z0": "row 1400", "z2": "job"}}},
              {"row": 1800, "emit": false, "p_emit": false, "read": {"o": {}, "p_emit": {"coolant": "job"}}}]}
A value read from "row K" is that row's `computed` value. Keys that do not apply are left out:
"calc" only for rows with `s`, "emit" only for rows with `o`. Values that are not plain JSON
(tool paths, long texts, integers beyond 64 bits) are summarised. The trace of one program keeps
at most MAX_TRACE_BYTES of row entries (a program is stored with its trace, and a template of a
few hundred rows each computing hundreds of values would otherwise store hundreds of MB); the
rows after the first that no longer fits are counted, not kept:
    "omitted": {"from_row": 90123, "rows": 178}
"""
from __future__ import annotations

import json
import math

import msgspec

MAX_TEXT = 200        # characters of a text value kept in the trace
MAX_LISTED = 8        # elements of a list or tuple kept in the trace; longer ones are summarised
MAX_INT_BITS = 64     # bits of an integer kept in the trace; longer ones are summarised
MAX_TRACE_BYTES = 1 << 20   # bytes of JSON of the row entries one program's trace keeps
MISSING = object()


class Outcome(msgspec.Struct, frozen=True):
    """What a row did for one set of inputs: the values it computed, its line and whether it
    was emitted, its trace entry, and the (origin, name, value) of each input it read from the
    job or a module (the program's trace keeps those values once)."""
    assignments: tuple[tuple[str, object], ...]
    line: object
    emit: bool
    trace: dict
    inputs: tuple[tuple[str, str, object], ...] = ()
    trace_bytes: int = 0   # the length of `trace` as JSON


class RowTrace:
    """Collects one row's entry while the row is evaluated."""

    def __init__(self, row, scope: dict, origin):
        self.row, self.scope, self.origin = row, scope, origin
        self.entry = {"row": row.row.id}
        self.assignments: list[tuple[str, object]] = []
        self.assigned: set[str] = set()
        self.inputs: list[tuple[str, str, object]] = []

    def read(self, column: str, expression) -> None:
        """Where each input `expression` reads comes from (and the value, when not from a row)."""
        reads = self.entry.setdefault("read", {}).setdefault(column, {})
        scope = self.scope
        for name in expression.ordered_names:
            if name in scope:
                origin = reads[name] = self._origin(name)
                if not origin.startswith("row "):
                    self.inputs.append((origin, name, json_value(scope[name])))

    def condition(self, column: str, value) -> bool:
        self.entry[column] = json_value(value)
        return bool(value)

    def computed(self, name: str, value):
        self.assignments.append((name, value))
        self.assigned.add(name)
        self.entry.setdefault("computed", {})[name] = json_value(value)
        return value

    def outcome(self, calc: bool | None, line=None, emit: bool | None = None) -> Outcome:
        if calc is not None:
            self.entry["calc"] = calc
        if line is not None:
            self.entry["emit"] = bool(emit)
        return Outcome(tuple(self.assignments), line, bool(emit), self.entry, tuple(self.inputs),
                       len(json.dumps(self.entry)))

    def _origin(self, name: str) -> str:
        if name in self.assigned:
            return f"row {self.row.row.id}"
        return self.origin(name)


def json_value(value):
    """A value as the trace keeps it: plain JSON values as they are, others summarised."""
    kind = type(value)
    if kind is int and value.bit_length() > MAX_INT_BITS:
        return f"<integer of {value.bit_length()} bits>"
    if kind is int or kind is bool or value is None or (kind is str and len(value) <= MAX_TEXT and "\x00" not in value):
        return value
    if kind is float and math.isfinite(value):
        return value
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return json_value(int(value))
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, str):   # PostgreSQL's jsonb holds no NUL
        text = value.replace("\x00", "\\x00")
        return text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + f"… ({len(value)} characters)"
    if isinstance(value, (list, tuple)):
        if len(value) <= MAX_LISTED and all(not isinstance(item, (list, tuple, dict)) for item in value):
            return [json_value(item) for item in value]
        return f"<{type(value).__name__} of {len(value)}>"
    return f"<{type(value).__name__}>"


def keep_entry(trace: dict, outcome: Outcome, kept: int) -> int:
    """The row's entry appended to the program's trace (which holds `kept` bytes of entries)
    while the trace stays within MAX_TRACE_BYTES; from the first entry that does not fit on,
    the rows are only counted. The bytes the trace then holds."""
    omitted = trace.get("omitted")
    if omitted is None and kept + outcome.trace_bytes <= MAX_TRACE_BYTES:
        trace["rows"].append(outcome.trace)
        return kept + outcome.trace_bytes
    if omitted is None:
        trace["omitted"] = {"from_row": outcome.trace["row"], "rows": 1}
    else:
        omitted["rows"] += 1
    return kept


MEMO_TEXT = 256   # characters of a text input that may be part of a memo key


def memo_key(row, scope: dict, origin) -> tuple | None:
    """The row and the exact values and origins of its inputs, or None unless every input is a
    plain scalar (a number, a short text, a truth value, None): rows with equal keys have equal
    outcomes. Equal keys only for values that print alike: the type is part of the key (1, 1.0
    and True are equal in Python) and floats are compared by their bits (0.0 and -0.0 are not)."""
    key = [row.row.id]
    for name in row.inputs:
        value = scope.get(name, MISSING)
        kind = type(value)
        if kind is float:
            key.append((float, value.hex()))
        elif kind is str and len(value) <= MEMO_TEXT:
            key.append(value)
        elif kind is int and value.bit_length() <= 64 or kind is bool or value is None:
            key.append((kind, value))
        else:
            return None
        key.append(origin(name))
    return tuple(key)
