"""Why each line of a program appeared, or did not, and with which values: the program's trace
(engine.templates.trace) read back, one sentence per template row.

    1800 not emitted: p_emit coolant = False (job)
    1500 EGON(C,"FINE",B,-1,19) emitted: coupling_b = -1 (job), z2 = 19 (job)
    1320 not emitted: p_emit shift_per_part = 0.0 (job)
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..nc.lineage import LINEAGE_ROW_ID

if TYPE_CHECKING:
    from ..db.connection import Connection

MAX_LISTED_LINES = 1   # lines of a row quoted in its sentence (a tool path prints hundreds)


class ExplainedRow(msgspec.Struct, frozen=True):
    row_id: int
    state: str           # emitted | not emitted | skipped | computed
    lines: tuple[str, ...]
    entry: dict          # the row's trace entry as stored
    read: dict           # column -> {name: [value, origin]}, the values looked up

    def sentence(self) -> str:
        return f"{self.row_id} {_what(self)}{_because(self)}"

    def as_dict(self) -> dict:
        return {"row": self.row_id, "state": self.state, "lines": list(self.lines), "read": self.read,
                **{key: value for key, value in self.entry.items() if key not in ("row", "read")}}


def explained_rows(trace: dict, lines: list[str], row_ids: list[int], row: int | None = None) -> list[ExplainedRow]:
    """Each row of the trace (or only `row`) with its state, the lines it emitted and the values
    it read. The lineage line (row id -1) is the engine's, no row's: it is in no trace."""
    emitted: dict[int, list[str]] = {}
    for line, row_id in zip(lines, row_ids):
        emitted.setdefault(row_id, []).append(line)
    computed = {f"row {entry['row']}": entry.get("computed", {}) for entry in trace["rows"]}
    values = {**trace["inputs"], **computed}
    entries = [entry for entry in trace["rows"] if row is None or entry["row"] == row]
    omitted = trace.get("omitted")
    if row is not None and not entries and omitted is not None and row >= omitted["from_row"]:
        raise EngineError(f"row {row} is beyond what the program's trace keeps (it keeps the rows before "
                          f"row {omitted['from_row']}); see `engine explain --program ID`")
    if row == LINEAGE_ROW_ID:
        raise EngineError(f"row {row} is the program's lineage line, written by the engine, not by a template row "
                          "(`; PROGRAM <id> TEMPLATE …`); see `engine programs show ID`")
    if row is not None and not entries:
        raise EngineError(f"row {row} is not in the program's template version; see `engine explain --program ID`")
    return [ExplainedRow(entry["row"], _state(entry), tuple(emitted.get(entry["row"], ())), entry,
                         _values_read(entry, values)) for entry in entries]


def _values_read(entry: dict, values: dict) -> dict:
    return {column: {name: [values.get(origin, {}).get(name), origin] for name, origin in reads.items()}
            for column, reads in entry.get("read", {}).items()}


def explain_program(conn: Connection, program_id: int, row: int | None = None) -> list[ExplainedRow]:
    """The stored program's rows, explained from its stored trace; refused unless the program is
    the rendering of the version and job it names (engine.programs.rendering)."""
    return traced_lines(conn, program_id, row)[0]


def traced_lines(conn: Connection, program_id: int, row: int | None = None) -> tuple[list[ExplainedRow], list[int]]:
    """explain_program's rows, and the template row of each of the program's lines (the lineage
    line's is LINEAGE_ROW_ID): what leads from a line on a screen to why it is there (engine serve)."""
    from .rendering import checked_program

    found = conn.execute("SELECT lines, row_ids, trace FROM program WHERE id = %s", (program_id,)).fetchone()
    if found is None:
        raise EngineError(f"program {program_id} does not exist; see `SELECT id, name FROM program`")
    checked_program(conn, program_id, "explain")   # its trace would narrate lines no template made
    lines, row_ids, trace = found
    if trace is None:
        raise EngineError(f"program {program_id} has no trace stored (NULL); "
                          "make it again with `engine instantiate --job ID` to explain it")
    return explained_rows(trace, lines, row_ids, row), list(row_ids)


def _state(entry: dict) -> str:
    if entry.get("calc") is False:
        return "skipped"
    if "emit" in entry:
        return "emitted" if entry["emit"] else "not emitted"
    return "computed"


def _what(row: ExplainedRow) -> str:
    if row.state != "emitted":
        return f"{row.state}"
    shown = " | ".join(row.lines[:MAX_LISTED_LINES])
    more = f" (+{len(row.lines) - MAX_LISTED_LINES} lines)" if len(row.lines) > MAX_LISTED_LINES else ""
    return f"{shown}{more} emitted"


def _because(row: ExplainedRow) -> str:
    """The decisive condition and the values that decided, or the inputs of the line."""
    entry, read = row.entry, row.read
    if row.state == "skipped":
        return f": p_calc {_inputs(read.get('p_calc'))}"
    if row.state == "not emitted":
        return f": p_emit {_inputs(read.get('p_emit'))}"
    parts = []
    if entry.get("computed"):
        parts.append("computed " + ", ".join(f"{name} = {_value(value)}" for name, value in entry["computed"].items()))
    own = f"row {row.row_id}"   # a value the row computed itself is shown as computed, not as an input
    inputs = {name: value_origin for column in ("p_calc", "s", "o", "p_emit")
              for name, value_origin in read.get(column, {}).items() if value_origin[1] != own}
    if inputs:
        parts.append(("from " if entry.get("computed") else "") + _inputs(inputs))
    return (": " + " ".join(parts)) if parts else ""


def _inputs(reads: dict | None) -> str:
    if not reads:
        return "(no inputs)"
    return ", ".join(f"{name} = {_value(value)} ({origin})" for name, (value, origin) in reads.items())


def _value(value) -> str:
    """JSON values written as a template engineer writes them in an expression."""
    if value is True or value is False or value is None:
        return {True: "True", False: "False", None: "None"}[value]
    return repr(value) if isinstance(value, (str, list)) else f"{value}"
