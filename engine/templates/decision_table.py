"""The expression-driven decision table (design notes §4, paper §3.2).

For each row in id order, with scope = job parameters ∪ parameters of module (T, N)
∪ intermediate variables computed so far:
1. if `s` is present: run it when `p_calc` is absent or true, else skip the whole row;
2. evaluate `o` to a string (absent `o`: the row only computes);
3. append it to the result when `p_emit` is absent or true.
asteval evaluates every expression (engine.templates.evaluator). Each row's outcome goes
into the program's trace (engine.templates.trace). A row whose inputs have the same values
and origins as for an earlier job of the template has the same outcome: it is taken from
the template's memo instead of being evaluated again (and pays again what it cost). A run spends
one budget of time and bytes (engine.templates.budget). Any failure aborts the whole
instantiation with an error naming class, row, column, text.
"""
from __future__ import annotations

import threading
from functools import partial
from typing import Any

import msgspec

from ..errors import EngineError
from .budget import Budget, compiling, pay_time, seconds_for, spending
from .evaluator import EvaluationError, Evaluator, base_symbols
from .expressions import Compiled, ExpressionError, compile_expression, compile_statements
from .guards import MAX_STRING_LENGTH, short_repr, size
from .nc_path import NcLines
from .rows import Template, TemplateRow
from .trace import Outcome, RowTrace, keep_entry, memo_key

MAX_MEMO_ROWS = 50_000    # outcomes kept per template (about 1.5 KB each); the memo starts again when full
MAX_MEMO_VALUE = 256      # characters or elements of a value an outcome kept in the memo may hold


class TemplateError(EngineError):
    """An expression of a template row failed: names class, row id, column and text."""

    def __init__(self, gear_class: str, row_id: int, column: str, text: str, problem: str):
        self.gear_class, self.row_id, self.column, self.text = gear_class, row_id, column, text
        super().__init__(f"class {gear_class} row {row_id} column {column}: {problem} in {short_repr(text)}")


class CompiledRow(msgspec.Struct, frozen=True):
    """A template row with its expressions parsed and checked, ready to run for a job."""
    row: TemplateRow
    o: Compiled | None
    p_calc: Compiled | None
    s: tuple[tuple[str, Compiled], ...]
    p_emit: Compiled | None
    inputs: tuple[str, ...] = ()   # names the row reads before assigning them: its memo key

    @property
    def module(self) -> tuple[str, int]:
        return self.row.t, self.row.n


class Result(msgspec.Struct):
    """The result table of one instantiation: emitted lines, the row id of each, and the trace
    (engine.templates.trace): the input values by origin, and an entry for every row."""
    lines: list[Any] = []   # text; an nc_path row's NcLines until _one_line_each
    row_ids: list[int] = []
    trace: dict = msgspec.field(default_factory=lambda: {"inputs": {}, "rows": []})


class CompiledTemplate:
    """A template parsed and checked once; `run` evaluates it for one job."""

    def __init__(self, template: Template):
        self.template = template
        with compiling(len(template.rows)):
            self.rows = tuple(compile_row(template.gear_class, row, template.translations) for row in template.rows)
        self.symbols = base_symbols(any(c.is_sql for r in self.rows for c in _expressions_of(r)))
        self._evaluators = threading.local()   # runners may share a process (and this compiled template)
        self.memo: dict[tuple, tuple[Outcome, int]] = {}   # key -> (outcome, bytes it cost to evaluate)
        # Rows that print a whole tool path (nc_path) emit several lines at once.
        self.prints_paths = any(row.o is not None and "nc_path" in row.o.calls for row in self.rows)

    def run(self, params: dict, module_params: dict | None = None, deadline_seconds: float | None = None,
            traced: bool = True) -> Result:
        """The job's program; `traced=False`: its lines and row ids alone, the trace left empty (the
        release impact compares and proves the lines of thousands of jobs and stores nothing)."""
        seconds = seconds_for(len(self.rows)) if deadline_seconds is None else deadline_seconds
        job = _Job(self, params, module_params or {}, Budget(seconds), traced)
        try:
            with spending(job.budget):
                for row in self.rows:
                    job.run_row(row)
        finally:
            job.evaluator.forget()
        return _one_line_each(job.result) if self.prints_paths else job.result

    @property
    def evaluator(self) -> Evaluator:
        """This thread's interpreter: one evaluation's scope and failures are its own."""
        if not hasattr(self._evaluators, "evaluator"):
            self._evaluators.evaluator = Evaluator()
        return self._evaluators.evaluator

    def remembered(self, key) -> tuple[Outcome, int] | None:
        return self.memo.get(key) if key is not None else None

    def remember(self, key, outcome: Outcome, cost: int) -> None:
        """Outcomes whose values are small: the memo keeps no large value alive."""
        values = [value for _, value in outcome.assignments] + [outcome.line]
        if key is not None and not any(isinstance(value, (str, tuple, list)) and size(value, MAX_MEMO_VALUE)
                                       > MAX_MEMO_VALUE for value in values):
            if len(self.memo) >= MAX_MEMO_ROWS:
                self.memo.clear()
            self.memo[key] = outcome, cost


class _Job:
    """The state of one run: scope, intermediates and where each came from, module switching."""

    def __init__(self, compiled: CompiledTemplate, params: dict, module_params: dict, budget: Budget,
                 traced: bool = True):
        self.compiled, self.params, self.module_params, self.traced = compiled, params, module_params, traced
        _refuse_engine_names(compiled, params, "job parameter")
        self.scope = {**params, **compiled.symbols, "template_version": compiled.template.version}
        self.intermediates: dict[str, int] = {}      # name -> id of the row that computed it
        self.module: tuple[str, int] | None = None   # (T, N) of the module the rows are in
        self.module_names: tuple[str, ...] = ()
        self.module_key: str | None = None
        self.budget, self.evaluator = budget, compiled.evaluator
        self.result, self.trace_bytes = Result(), 0

    def run_row(self, row: CompiledRow) -> None:
        if row.module != self.module:
            self._enter(row.module)
        key = memo_key(row, self.scope, self.origin)
        remembered = self.compiled.remembered(key)
        if remembered is None:
            self._pay(row, 0)
            spent = self.budget.spent
            outcome = self._evaluate(row)
            self.compiled.remember(key, outcome, self.budget.spent - spent)
        else:
            outcome, cost = remembered
            self._pay(row, cost)
        self._apply(row, outcome)

    def _pay(self, row: CompiledRow, cost: int) -> None:
        """The row's turn: within the run's time, and what its outcome cost when it was evaluated."""
        try:
            self.budget.pay(cost)
        except (TimeoutError, ValueError) as error:
            column = "s" if row.row.s else "o"
            raise TemplateError(self.compiled.template.gear_class, row.row.id, column, getattr(row.row, column) or "",
                                str(error)) from None

    def origin(self, name: str) -> str:
        """Where a name's value comes from: the row that computed it, the module, the job."""
        if name in self.intermediates:
            return f"row {self.intermediates[name]}"
        if name in self.module_names:
            return f"module {self.module_key}"
        return "template" if name == "template_version" else "job"

    def _enter(self, module: tuple[str, int]) -> None:
        """Module (T, N) parameters in, the previous module's out; intermediates stay."""
        self.module, key = module, f"{module[0]}:{module[1]}"
        if not self.module_names and key not in self.module_params:
            return
        for name in self.module_names:
            if name not in self.intermediates:
                if name in self.params:
                    self.scope[name] = self.params[name]
                else:
                    self.scope.pop(name, None)
        current = self.module_params.get(key) or {}
        _refuse_engine_names(self.compiled, current, f"parameter of module {key}")
        self.module_names, self.module_key = tuple(current), key
        for name, value in current.items():
            if name not in self.intermediates:
                self.scope[name] = value

    def _evaluate(self, row: CompiledRow) -> Outcome:
        """Evaluate the row in the current scope (its statements' values enter it as they run)."""
        trace = RowTrace(row, self.scope, self.origin)
        if row.s:
            if row.p_calc is not None and not trace.condition("p_calc", self._value(row, "p_calc", row.p_calc, trace)):
                return trace.outcome(calc=False)
            for name, expression in row.s:
                self.scope[name] = trace.computed(name, self._value(row, "s", expression, trace))
        if row.o is None:
            return trace.outcome(calc=bool(row.s) or None)
        line = _text(self._value(row, "o", row.o, trace), row, self.compiled.template.gear_class)
        emit = row.p_emit is None or trace.condition("p_emit", self._value(row, "p_emit", row.p_emit, trace))
        return trace.outcome(calc=bool(row.s) or None, line=line, emit=emit)

    def _value(self, row: CompiledRow, column: str, expression: Compiled, trace):
        trace.read(column, expression)
        try:
            self.budget.check_time()   # between expressions too: a row may hold many
            return self.evaluator.evaluate(expression.tree, expression.text, self.scope)
        except (TimeoutError, EvaluationError) as error:
            raise TemplateError(self.compiled.template.gear_class, row.row.id, column, expression.text,
                                str(error)) from None

    def _apply(self, row: CompiledRow, outcome: Outcome) -> None:
        for name, value in outcome.assignments:
            self.scope[name] = value
            self.intermediates[name] = row.row.id
        if outcome.emit:
            self.result.lines.append(outcome.line)
            self.result.row_ids.append(row.row.id)
        if not self.traced:
            return
        inputs = self.result.trace["inputs"]
        for origin, name, value in outcome.inputs:
            inputs.setdefault(origin, {})[name] = value
        self.trace_bytes = keep_entry(self.result.trace, outcome, self.trace_bytes)


def _refuse_engine_names(compiled: CompiledTemplate, names, what: str) -> None:
    """No job or module parameter may rebind a function, constant or guard of the engine."""
    clash = sorted(name for name in names if name in compiled.symbols or name == "template_version")
    if clash:
        raise EngineError(f"class {compiled.template.gear_class}: {what} {short_repr(clash[0])} has the name of a "
                          "function or constant of the engine; rename it")


def _one_line_each(result: Result) -> Result:
    """The blocks of an nc_path row as lines of their own, each with the row's id."""
    flat = Result(trace=result.trace)
    for line, row_id in zip(result.lines, result.row_ids):
        if isinstance(line, NcLines):
            flat.lines.extend(line)
            flat.row_ids.extend([row_id] * len(line))
        else:
            flat.lines.append(line)
            flat.row_ids.append(row_id)
    return flat


def _text(value, row: CompiledRow, gear_class: str):
    """`o` must give text (a bare number would print in whatever form Python chooses), of
    bounded length; or the blocks of nc_path."""
    if isinstance(value, NcLines):
        return value
    if type(value) is not str:
        problem = (f"gives {type(value).__name__} {short_repr(value)}, not text "
                   "(write an f-string with a format, e.g. f\"X{x:.3f}\")")
    elif len(value) > MAX_STRING_LENGTH:
        problem = f"gives a line longer than {MAX_STRING_LENGTH} characters"
    else:
        return value
    assert row.o is not None   # the value is the row's o
    raise TemplateError(gear_class, row.row.id, "o", row.o.text, problem[:300])


_ONCE = threading.local()


class rows_compiled_once:
    """`with rows_compiled_once():` each row compiled in the block is compiled once, however often
    it is checked and run (an import checks its rows before storing them, then instantiates them),
    and each body (p_calc, s, o, p_emit) once however many rows hold it: the gate's verdict and
    the guarded trees depend on the texts alone, and a long program repeats its lines (a
    100,000-line lathe program has 49,000 distinct ones: `T0101`, `G96 S200 M03` in every
    operation). A body that is refused is not kept: each row holding it is refused again."""

    def __enter__(self):
        self.outer = getattr(_ONCE, "rows", None), getattr(_ONCE, "bodies", None)
        _ONCE.rows, _ONCE.bodies = {}, {}

    def __exit__(self, *exc) -> None:
        _ONCE.rows, _ONCE.bodies = self.outer


def compile_row(gear_class: str, row: TemplateRow, translations=None) -> CompiledRow:
    """The row's expressions checked and guarded (SQL conditions from their stored translations
    where `translations` has them), within the time of the compile running (engine.templates.budget)."""
    try:
        pay_time()
    except TimeoutError as error:
        column = "s" if row.s else "o"
        raise TemplateError(gear_class, row.id, column, getattr(row, column) or "", str(error)) from None
    remembered = getattr(_ONCE, "rows", None)
    if remembered is None or translations:
        return _compile_row(gear_class, row, translations)
    key = gear_class, row
    if key not in remembered:
        remembered[key] = _compiled_body(gear_class, row)
    return remembered[key]


def _compiled_body(gear_class: str, row: TemplateRow) -> CompiledRow:
    """The row with the compiled expressions of the first row of its body (rows_compiled_once)."""
    body = row.p_calc, row.s, row.o, row.p_emit
    known = _ONCE.bodies.get(body)
    if known is None:
        compiled = _ONCE.bodies[body] = _compile_row(gear_class, row)
        return compiled
    return CompiledRow(row, known.o, known.p_calc, known.s, known.p_emit, known.inputs)


def _compile_row(gear_class: str, row: TemplateRow, translations=None) -> CompiledRow:
    expression = partial(compile_expression, translations=translations)

    def compiled(column: str, compile_function):
        text = getattr(row, column)
        if text is None:
            return None
        try:
            return compile_function(text)
        except (ExpressionError, TimeoutError) as error:
            raise TemplateError(gear_class, row.id, column, text, str(error)) from None

    statements = tuple(compiled("s", compile_statements) or ())
    p_calc = compiled("p_calc", expression)
    o, p_emit = compiled("o", expression), compiled("p_emit", expression)
    return CompiledRow(row, o, p_calc, statements, p_emit,
                       _inputs(p_calc if statements else None, statements, o, p_emit))


def _inputs(p_calc, statements, o, p_emit) -> tuple[str, ...]:
    """Names the row reads before it assigns them itself, in evaluation order."""
    seen: dict[str, None] = {}   # an ordered set
    assigned = set()
    for expression, target in [(p_calc, None), *((value, name) for name, value in statements), (o, None),
                               (p_emit, None)]:
        if expression is not None:
            seen.update((name, None) for name in sorted(expression.names) if name not in assigned)
        if target is not None:
            assigned.add(target)
    return tuple(seen)


def _expressions_of(row: CompiledRow):
    for compiled in (row.o, row.p_calc, row.p_emit):
        if compiled is not None:
            yield compiled
    for _, compiled in row.s:
        yield compiled


_CACHE: dict[tuple, CompiledTemplate] = {}


def compiled_template(template: Template) -> CompiledTemplate:
    """Parse every expression once per template (keyed by class, version, content and the stored
    translations of its SQL conditions, which the gate checks again when they change)."""
    key = template.cache_key
    found = _CACHE.get(key)
    if found is None:
        found = _CACHE[key] = CompiledTemplate(template)
    return found
