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
(tool paths, long texts) are summarised.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

MAX_TEXT = 200        # characters of a text value kept in the trace
MAX_LISTED = 8        # elements of a list or tuple kept in the trace; longer ones are summarised
MISSING = object()


@dataclass(frozen=True)
class Outcome:
    """What a row did for one set of inputs: the values it computed, its line and whether it
    was emitted, its trace entry, and the (origin, name, value) of each input it read from the
    job or a module (the program's trace keeps those values once)."""
    assignments: tuple[tuple[str, object], ...]
    line: object
    emit: bool
    trace: dict
    inputs: tuple[tuple[str, str, object], ...] = ()


class RowTrace:
    """Collects one row's entry while the row is evaluated."""

    def __init__(self, row, scope: dict, origin):
        self.row, self.scope, self.origin = row, scope, origin
        self.entry = {"row": row.row.id}
        self.assignments: list[tuple[str, object]] = []
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
        self.entry.setdefault("computed", {})[name] = json_value(value)
        return value

    def outcome(self, calc: bool | None, line=None, emit: bool | None = None) -> Outcome:
        if calc is not None:
            self.entry["calc"] = calc
        if line is not None:
            self.entry["emit"] = bool(emit)
        return Outcome(tuple(self.assignments), line, bool(emit), self.entry, tuple(self.inputs))

    def _origin(self, name: str) -> str:
        if any(name == assigned for assigned, _ in self.assignments):
            return f"row {self.row.row.id}"
        return self.origin(name)


def row_trace(row, scope: dict, origin) -> RowTrace:
    return RowTrace(row, scope, origin)


def json_value(value):
    """A value as the trace keeps it: plain JSON values as they are, others summarised."""
    kind = type(value)
    if kind is int or kind is bool or value is None or (kind is str and len(value) <= MAX_TEXT):
        return value
    if kind is float and math.isfinite(value):
        return value
    if isinstance(value, (bool, int)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, str):
        return value if len(value) <= MAX_TEXT else value[:MAX_TEXT] + f"… ({len(value)} characters)"
    if isinstance(value, (list, tuple)):
        if len(value) <= MAX_LISTED and all(not isinstance(item, (list, tuple, dict)) for item in value):
            return [json_value(item) for item in value]
        return f"{type(value).__name__} of {len(value)}"
    return f"{type(value).__name__}"


def memo_key(row, scope: dict, origin) -> tuple | None:
    """The row and the exact values and origins of its inputs, or None if a value cannot be a key
    (a list): rows with equal keys have equal outcomes."""
    key = [row.row.id]
    for name in row.inputs:
        key.append(_token(scope.get(name, MISSING)))
        key.append(origin(name))
    key = tuple(key)
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _token(value):
    """Equal tokens only for values that print alike: the type is part of it (1, 1.0 and True
    are equal in Python) and floats are compared by their bits (0.0 and -0.0 are not)."""
    if type(value) is float:
        return float, value.hex()
    if type(value) is tuple:
        return tuple, tuple(_token(item) for item in value)
    return value if type(value) is str else (type(value), value)
