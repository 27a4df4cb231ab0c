"""Importing a proven NC program as the standard code of a class (design notes §4, §5).

Each line of the file becomes one template row, ids 10, 20, 30 … in line order. A number
in the line whose value equals a job parameter (compared as Decimal: `F250.` matches 250)
becomes a reference to that parameter when the parameter binds the number's address
(engine.library.nc_params: a plain parameter binds every address but G M N O T $, a bound one
only the addresses it names); labels, comments and strings never do. An equal number at an
address its parameter does not bind is left as written and reported (`left_alone`), and the
report lists every parameter with the words it bound. A line with no reference is a
constant row (`o` = a plain string literal); a line with references is an f-string.

Exact values (issue 27): the field that replaces a number is `{nc_number(p, 'style')}`
(engine.templates.nc_number), the style read off the number as written (`0.010` → `#.000`,
`250.` → `#.`, `-00500` → `000000`, `+5` → `+#`, `.4` → `.0`). The imported value prints as the
file wrote it; another value prints its own digits (the shortest exact decimal), with at least the
file's decimals and the file's point, padding and sign: feed 0.025 in the style of `F0.010` is
`F0.025`, 31.25 in the style of `F31.` is `F31.25`. It is never rounded: a value with more
significant digits than an NC word holds is refused when the class is instantiated, with the reason.
Every field is evaluated with the original value before it is used; a number it would not give
back (a float that cannot hold all its digits, more digits than a word holds), and a negative
zero (`J-0`: the sign is not in the value), stay literal. When several parameters that bind a
number's address have its value, the first one given is used (reported).

Literal text is quoted exactly: backslashes and the quote character are escaped, braces
doubled inside f-strings. A tab is refused with its line (refuse_tabs: no program line holds one).

Modules: the rules of MODULE_RULES decide a line's module type from its tokens, in order;
a line no rule decides keeps the module of the line before (the first line: main). The
engineer's corrections (`modules`: line number → type) are decisions too, so the lines
after a corrected line follow it until a rule decides otherwise. N counts, per type, the
runs of that type: it increases each time the type recurs after another type.

Lines: the file is split at its line ending, LF or CRLF (a final newline ends the last line, it
adds no empty line); the rows hold the lines without endings, and the class keeps the ending
and whether the file had a final newline (engine.nc.layout; a file mixing LF and CRLF
is refused). Instantiating the import with the same parameters and writing the lines with that
layout (nc_text) gives the file byte for byte. The import checks this itself before it commits
(engine.library.nc_verify), while
the rows are being written.
"""
from __future__ import annotations

import json
import keyword
import re
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import asdict
from psycopg.types.json import Jsonb

from ..csv_reader import Column, CsvKind, parse_number_or_text, parse_text, parse_whole, read_csv_file, refuse
from ..errors import EngineError
from ..memory import no_cycle_collection
from ..names import shown
from ..nc.layout import NcLayout, split_nc_text, store_layout
from ..nc.lineage import ENGINES_LINE, first_lineage_shaped
from ..nc.tokens import LABEL, SYMBOL, LineFacts
from ..templates.functions import CONSTANTS, FUNCTIONS
from ..templates.rows import MODULE_ORDER, TemplateRow
from ..templates.store import ensure_class, load_template, replace_template
from ..templates.versions import released_version
from .nc_halves import in_halves
from .nc_params import binding_report, bindings, parse_addresses, refuse_blank_params, values
from .nc_rows import Builder, Found
from .nc_verify import Proof

if TYPE_CHECKING:
    from ..db.connection import Connection

CLASS_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
ROW_STEP = 10


class ImportReport(msgspec.Struct):
    gear_class: str
    path: str
    rows: int
    parameterised: int                      # numbers turned into parameter references
    modules: dict                           # module type → rows
    created: bool
    changed: bool
    version: int
    ambiguous: dict = {}   # value → parameters having it (first used)
    released_version: int | None = None     # what runners get: the import is a draft until released
    bindings: list = []    # per parameter: its addresses and the words it bound
    left_alone: list = []  # equal numbers at addresses not bound: line, word, parameter


def import_nc(conn: Connection, path, gear_class: str, params: dict | None = None, modules: dict | None = None,
              parent: str | None = None) -> ImportReport:
    """Store the NC program at `path` as the template of `gear_class`: all or nothing."""
    with no_cycle_collection():   # tokens and checked trees of every line: millions of objects
        return _import(conn, path, gear_class, params, modules, parent)


def _import(conn: Connection, path, gear_class: str, params: dict | None, modules: dict | None,
            parent: str | None) -> ImportReport:
    if not CLASS_NAME.match(gear_class or ""):
        raise EngineError(f"class name {gear_class!r}: use lower-case letters, digits and _, "
                          "starting with a letter")
    check_param_names(params or {})
    refuse_blank_params(params or {})
    bound = bindings(params or {})
    params = values(params or {})
    lines, layout = read_nc_file(path)
    refuse_lineage(path, lines)
    halves = in_halves(len(lines), partial(_read_lines, lines, Builder(bound, path)))
    assigned = assign_modules([facts for half in halves for facts in half[0]], _checked_modules(modules, len(lines)))
    texts = [o for half in halves for o in half[1]]
    rows = [TemplateRow(ROW_STEP * (index + 1), t, n, None, None, o, None) for index, (o, (t, n)) in
            enumerate(zip(texts, assigned))]
    found = halves[0][2]
    for half in halves[1:]:
        found.add(half[2])
    proof = Proof(params, lines, path)
    with conn.transaction():
        created = ensure_class(conn, gear_class, parent)
        changed = replace_template(conn, gear_class, rows, check=proof.start_on)   # proved while written
        _store_import_params(conn, gear_class, params)
        changed = store_layout(conn, gear_class, layout) or changed   # a new layout is a new version too
        template = load_template(conn, gear_class)
        _refuse_inherited(template, lines)
        proof.verdict(template.rows)
    counts = {t: sum(1 for row in rows if row.t == t) for t in MODULE_ORDER}
    return ImportReport(gear_class, str(path), len(rows), found.parameterised,
                        {t: c for t, c in counts.items() if c}, created, changed, template.version,
                        found.ambiguous, released_version(conn, gear_class),
                        binding_report(bound, found.bound, found.bound_lines, found.left_lines),
                        [asdict(left) for left in found.left_alone])


def _read_lines(lines: list[str], built: Builder, start: int, end: int) -> tuple:
    """Lines start…end: the facts of each (for its module), its row's `o`, and what they gave
    (references, ambiguous values, words bound, numbers left alone). Each distinct text is read
    once (its tokens, facts and `o` are those of its text; a long program repeats `T0101` and
    `G96 S200 M03` in every operation, half of the lines of the bench's lathe program); what it
    gave is counted again at every line that holds it, with that line's number."""
    built.found = Found()
    line_facts, texts = [], []
    read: dict[str, tuple] = {}   # text -> (facts, o, what it gave: None for nothing)
    for number in range(start, end):
        known = read.get(lines[number])
        if known is None:
            known = read[lines[number]] = built.read(number + 1, lines[number])
        line_facts.append(known[0])
        texts.append(known[1])
        if known[2] is not None:
            built.found.add_line(known[2], number + 1)
    return line_facts, texts, built.found


def _store_import_params(conn: Connection, gear_class: str, params: dict) -> None:
    """Keep the parameters the class was imported with: lint checks its names against them."""
    conn.execute("UPDATE gear_class SET import_params = %s WHERE name = %s",
                 (Jsonb(params, dumps=_params_json), gear_class))


def _params_json(params: dict) -> str:
    try:
        return json.dumps(params, default=str, allow_nan=False)
    except ValueError:
        raise EngineError("parameter values must be finite: NaN and infinity cannot be stored; "
                          "give numbers or text") from None


def _refuse_inherited(template, lines: list[str]) -> None:
    """The class must be made of the program's rows alone."""
    inherited = [row.id for row in template.rows if row.id > ROW_STEP * len(lines) or row.id % ROW_STEP]
    if inherited:
        raise EngineError(f"class {template.gear_class} inherits rows {inherited[:5]} from its parent, so it "
                          "would not give the program back; import it under a parent without rows")


# --- reading -------------------------------------------------------------------------

def refuse_lineage(path, lines: list[str]) -> None:
    """A program printed by the engine carries its lineage line (`; PROGRAM 812 TEMPLATE …`, or a
    dry run's `DRY-RUN`): imported as a row, every program of the class would carry a second one,
    naming another program."""
    number = first_lineage_shaped(lines)
    if number is not None:
        raise EngineError(f"{path} line {number} is a lineage line {shown(lines[number - 1])}; "
                          f"remove that line and import the file again ({ENGINES_LINE})")


_CONTROL = re.compile(r"[\x00-\x08\x0b\x0e-\x1f\x7f]")


def read_nc_lines(path) -> list[str]:
    """The lines of a text NC file, without their endings."""
    return read_nc_file(path)[0]


def read_nc_file(path) -> tuple[list[str], NcLayout]:
    """The lines of a text NC file and its layout; a clear error for a missing, empty or binary file."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise EngineError(f"cannot read {path}: {error.strerror}; give an NC program file") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise EngineError(f"{path} is not UTF-8 text (byte 0x{data[error.start]:02x} at offset "
                          f"{error.start}); give a text NC program, converted to UTF-8") from None
    control = _CONTROL.search(text)
    if control:
        line = text.count("\n", 0, control.start()) + 1
        raise EngineError(f"{path} line {line} has control character 0x{ord(control.group()):02x}: "
                          "it is binary, not a text NC program")
    if not text.strip():
        raise EngineError(f"{path} is empty; give an NC program with at least one line")
    refuse_tabs(path, text)
    return split_nc_text(path, text)


def refuse_tabs(path, text: str) -> None:
    """A tab is refused where the program enters, naming its line (issue 27): the program record
    holds no control character in a line (check_program, migration 0010: every writer's program
    is one block per line of printable text), and not every control reads a tab as a space (a
    Fanuc's ISO code has no HT among its program characters). Accepted here, the class's every job
    would fail when stored; refused, the user converts the file once and it comes back byte for byte."""
    tab = text.find("\t")
    if tab >= 0:
        line = text.count("\n", 0, tab) + 1
        column = tab - text.rfind("\n", 0, tab)
        raise EngineError(f"{path} line {line} column {column} holds a tab: a stored NC line holds no control "
                          "character and not every control reads a tab; replace each tab with a space "
                          "(`expand -t 1 FILE`) and import the file again; nothing stored")


RESERVED_NAMES = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"template_version"}


PARAMS_KIND = CsvKind("parameter", (Column("name", parse_text, required=True),
                                    Column("value", parse_number_or_text),
                                    Column("addresses", parse_addresses, header_optional=True)), every_column=True)
MODULES_KIND = CsvKind("module type", (Column("line_no", parse_whole, required=True),
                                       Column("t", parse_text, required=True)))


def check_param_names(params: dict) -> None:
    for name in params:
        if not (isinstance(name, str) and name.isidentifier()) or keyword.iskeyword(name) \
                or name.startswith("_") or name in RESERVED_NAMES:
            raise EngineError(f"parameter name {name!r} cannot be used in a template expression; "
                              "use letters, digits and _ (not starting with _, not a function name)")


def read_params(path) -> dict:
    """Job parameters in either form of engine.library.nc_params, checked: a JSON object
    {name: value or {"value": …, "addresses": […]}}, or a CSV with columns name,value and an
    optional column addresses (`F`, `X Z`; empty: the plain form)."""
    if str(path).lower().endswith(".json"):
        params = _json_params(path, _read_text(path, "parameters file"))
    else:
        params = _csv_params(path)
    check_param_names(params)
    bindings(params, str(path))
    return params


def _json_params(path, text: str) -> dict:
    """The JSON object of a parameters file; a name given twice, nesting deeper than Python
    reads, or no object is refused in one line (NaN and Infinity by nc_params, naming the parameter)."""
    try:
        params = json.loads(text, object_pairs_hook=partial(_once, path))
    except json.JSONDecodeError as error:
        raise EngineError(f"{path}: not JSON ({error.msg}, line {error.lineno}); "
                          "give an object {\"name\": value, …}") from None
    except RecursionError:
        raise EngineError(f"{path}: nested too deep to read; give an object {{\"name\": value, …}} "
                          "whose values are numbers, text or {\"value\": …, \"addresses\": […]}") from None
    if not isinstance(params, dict):
        raise EngineError(f"{path}: give a JSON object {{\"name\": value, …}}, not {type(params).__name__}")
    return params


def _once(path, pairs: list) -> dict:
    """An object whose keys are each given once (JSON keeps the last silently; a CSV refuses)."""
    names = [name for name, _ in pairs]
    twice = next((name for name in names if names.count(name) > 1), None)
    if twice is not None:
        raise EngineError(f"{path}: {twice!r} appears twice in one object; give each parameter and key once")
    return dict(pairs)


def read_modules(path) -> dict[int, str]:
    """The engineer's module types for some lines: a CSV with columns line_no,t."""
    modules = {}
    file = read_csv_file(path, MODULES_KIND)
    for line, record in file.rows():
        line_no = _cell_value(file, MODULES_KIND.column("line_no"), record, line)
        if line_no in modules:
            raise refuse(path, f"program line {line_no} appears twice", "give each line once", line, "line_no")
        modules[line_no] = _cell_value(file, MODULES_KIND.column("t"), record, line)
    _checked_modules(modules, None)
    return modules


def _read_text(path, what: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or "not UTF-8 text"
        raise EngineError(f"cannot read {what} {path}: {reason}") from None


def _csv_params(path) -> dict:
    """{name: value} of a CSV with columns name,value (a number as int or float, else the text);
    a row with addresses gives {"value": value, "addresses": [...]}."""
    params: dict = {}
    file = read_csv_file(path, PARAMS_KIND)
    for line, record in file.rows():
        name = _cell_value(file, PARAMS_KIND.column("name"), record, line)
        if name in params:
            raise refuse(path, f"parameter {name!r} appears twice", "give each parameter once", line, "name")
        value = _cell_value(file, PARAMS_KIND.column("value"), record, line)
        addresses = _cell_value(file, PARAMS_KIND.column("addresses"), record, line)
        value = "" if value is None else value
        params[name] = {"value": value, "addresses": addresses} if addresses else value
    return params


def _cell_value(file, column, record: dict, line: int):
    value, problem = file.cell(column, record.get(column.name, ""), line)
    if problem:
        raise EngineError(problem.said(file.source))
    return value


def _checked_modules(modules: dict | None, line_count: int | None) -> dict:
    for line_no, t in (modules or {}).items():
        if t not in MODULE_ORDER:
            raise EngineError(f"modules: line {line_no} has module type {t!r}; use one of {', '.join(MODULE_ORDER)}")
        if line_no < 1 or (line_count is not None and line_no > line_count):
            raise EngineError(f"modules: line {line_no} is not a line of the program (1…{line_count or 'N'})")
    return dict(modules or {})


# --- module assignment -----------------------------------------------------------------

class _State(msgspec.Struct):
    seen_code: bool = False
    seen_cut: bool = False


SYNC_WORDS = frozenset({"EGDEF", "EGON", "EGONSYN", "EGONSYNE", "EGOFS", "EGOFC", "EGDEL"})
CUTCOND_CODES = frozenset({"M3", "M4", "M5", "M7", "M8", "M9"})
END_CODES = frozenset({"M2", "M30", "M17"})
PREP_CODES = frozenset({f"G{n}" for n in (7, 8, 17, 18, 19, 20, 21, 25, 26, 40, 41, 42, 43, 49,
                                          53, 54, 55, 56, 57, 58, 59, 64, 90, 91, 500, 700, 710)} | {"M6"})
PREP_WORDS = frozenset({"T", "WALIMON", "WALIMOF", "TRAFOOF", "TRAORI", "CYCLE800"})
CUT_CODES = frozenset({"G1", "G2", "G3"})


def _is_frame(f: LineFacts) -> bool:
    """`%` header, `O<name> sub`/`endsub`, a lone program number, the end of the program."""
    program_label = any(label.startswith("O") for label in f.labels) and (
        f.words & {"SUB", "ENDSUB"}
        or (len(f.labels) == 1 and f.first is not None and f.first.kind == LABEL and not f.words))
    starts_with_percent = f.first is not None and f.first.kind == SYMBOL and f.first.text == "%"
    return bool(starts_with_percent or program_label or f.codes & END_CODES or "PROC" in f.words)


# (module type, what it recognises, predicate over the line's facts and the state so far);
# the first rule that holds decides.
MODULE_RULES = (
    ("main", "program frame", lambda f, s: _is_frame(f)),
    ("main", "comments before the first block", lambda f, s: not s.seen_code and not f.has_code),
    ("sync", "electronic gearbox", lambda f, s: f.words & SYNC_WORDS),
    ("cutcond", "spindle, coolant, speed, feed alone",
     lambda f, s: f.codes & CUTCOND_CODES or "S" in f.words or ("F" in f.words and not f.axes)),
    ("prep", "limits, offsets, units, tool call", lambda f, s: f.codes & PREP_CODES or f.words & PREP_WORDS),
    ("shift", "G0 move of Y alone", lambda f, s: "G0" in f.codes and f.axes == {"Y"}),
    ("prep", "G0 positioning before the first cut", lambda f, s: "G0" in f.codes and not s.seen_cut),
    ("cutmotion", "G1/G2/G3 move", lambda f, s: f.codes & CUT_CODES),
    ("cutmotion", "G0 move after a cut", lambda f, s: "G0" in f.codes),
)


def assign_modules(lines: list[LineFacts], corrections: dict | None = None) -> list[tuple[str, int]]:
    """(t, n) of every line: by the engineer's correction, else by MODULE_RULES, else as before."""
    corrections = corrections or {}
    state, current, runs = _State(), "main", {t: 0 for t in MODULE_ORDER}
    assigned: list[tuple[str, int]] = []
    for number, line in enumerate(lines, start=1):
        decided = corrections.get(number) or next(
            (t for t, _, holds in MODULE_RULES if holds(line, state)), current)
        state.seen_code |= line.has_code
        state.seen_cut |= bool(line.codes & CUT_CODES)
        if decided != current or not assigned:
            runs[decided] += 1
        current = decided
        assigned.append((decided, runs[decided]))
    return assigned
