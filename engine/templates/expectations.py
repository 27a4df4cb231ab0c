"""The expectation language of golden tests (template_test.expect, one text per element), for
DBAs editing tests in SQL. A program is a list of lines (without the lineage line, which the
engine adds when it stores a program):

    line: M30                   this exact line is in the program (spaces at the ends ignored)
    no line: M8                 no line is exactly this
    line 3: G90 G71 G94         line 3 (1-based) is exactly this
    last line: M30              the last line is exactly this
    match: ^EGON\\(C,"FINE",B   at least one line matches the regular expression (anywhere in it)
    no match: ^G1 .*F0\\b       no line matches it
    <property> = <expression> [± <tolerance>]     (`+-` for ±)
        the property read from the program (engine.templates.program_properties) equals the
        expression, evaluated over the job's parameters (mn, z2, z0, da0, df2, beta, hand, …,
        see `engine explain`) with the engine's own checked evaluator (never Python's eval).
        Besides the job's parameters the expression may name h_hob and h_gear (+1 right hand,
        -1 left, 0 none: hobbing.md §A7), and for a gear test gear_<field> (gear_teeth, …) and
        unit<N>_<field> (unit2_teeth, …) of the gear record.
        Properties: `EGON ratio` (Z1/N1 of the B axis in the first EGON; `last EGON ratio`),
        `EGON Z factor` (any leading axis: `EGON Y factor`), `first|last|min|max [G0|G1] <address>`
        (e.g. `last X`, `max G1 X`: the values of that address over the blocks, optionally only
        blocks in that modal motion; G25/G26 limit blocks are not positions and are left out),
        `XZ slope` (dX/dZ of the last block moving X and Z),
        `count of G1` (blocks holding the word), `line count`.
        Default tolerance: 1e-6 plus half a unit in the last digit the program printed (0.0005
        for `X51.500`).

An expectation that cannot be read, a property no rule reads, or an expression that does not
evaluate (an unknown name) fails the test with that reason: it never passes.

Patterns are RE2's syntax and run by RE2 (google-re2), in time linear in the line (issue 26): a
pattern Python's backtracking `re` would take minutes over (`^(.+)+!$`) cannot hold `engine test`
or a release up. What RE2 cannot run in linear time (backreferences `\\1`, lookaround `(?=`,
`(?<=`) is refused when a test is seeded (`refuse_slow_patterns`) and fails the test when it
runs (a DBA may have written it in SQL). The expectation texts themselves are read by RE2 too.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import msgspec
import re2  # type: ignore[import-untyped]   # google-re2 ships no stubs

from ..errors import EngineError
from .evaluator import evaluate
from .program_properties import Reading, UnknownProperty, property_reader, read_property

if TYPE_CHECKING:
    from collections.abc import Callable

ABSOLUTE_TOLERANCE = 1e-6
RE2_OPTIONS = re2.Options()
RE2_OPTIONS.log_errors = False   # a refused pattern is said in one line, not logged to stderr too
TEXT_KINDS = tuple((re2.compile(pattern, RE2_OPTIONS), kind) for pattern, kind in (
    # (pattern, kind); the first that matches the expectation's text wins
    (r"(?s)no line:\s?(.*)", "no line"),
    (r"(?s)last line:\s?(.*)", "last line"),
    (r"(?s)line (\d+):\s?(.*)", "line n"),
    (r"(?s)line:\s?(.*)", "line"),
    (r"(?s)no match:\s?(.*)", "no match"),
    (r"(?s)match:\s?(.*)", "match"),
))
NUMERIC = re2.compile(r"(?P<property>[^=]+?)\s*=\s*(?P<expression>.+?)(?:\s*(?:±|\+-)\s*(?P<tolerance>\S+))?\s*",
                      RE2_OPTIONS)


class ExpectationError(EngineError):
    """An expectation that cannot be read or evaluated: the test fails with this reason."""


class Context(msgspec.Struct, frozen=True):
    """What an expectation is checked against: the program's lines and the names its
    expressions may read."""
    lines: list[str]
    names: dict


def check(expectation: str, context: Context) -> str | None:
    """None if the program meets the expectation, else the first difference in one line."""
    text = expectation.strip()
    kind, groups = _text_kind(text)
    if kind is not None:
        return TEXT_CHECKS[kind](*groups, lines=context.lines)
    numeric = NUMERIC.fullmatch(text)
    if numeric is None:
        raise ExpectationError(f"cannot read expectation {text!r}: write `line: …`, `no line: …`, `match: …`, "
                               "`no match: …` or `<property> = <expression> [± tolerance]`")
    return check_numeric(numeric.group("property"), numeric.group("expression"), numeric.group("tolerance"),
                         context)


def _text_kind(text: str) -> tuple[str | None, tuple]:
    """The kind of a text expectation and what it names, (None, ()) for a numeric one."""
    for pattern, kind in TEXT_KINDS:
        match = pattern.fullmatch(text)
        if match:
            return kind, match.groups()
    return None, ()


def _line_present(wanted: str, lines: list[str]) -> str | None:
    return None if wanted.strip() in _stripped(lines) else "program has no such line"


def _line_absent(unwanted: str, lines: list[str]) -> str | None:
    stripped = _stripped(lines)
    if unwanted.strip() not in stripped:
        return None
    number = stripped.index(unwanted.strip()) + 1
    return f"program has it (line {number}: {lines[number - 1]})"


def _line_at(number: str, wanted: str, lines: list[str]) -> str | None:
    index = int(number) - 1
    if not 0 <= index < len(lines):
        return f"program has only {len(lines)} lines"
    return None if lines[index].strip() == wanted.strip() else f"program has line {number}: {lines[index]}"


def _last_line(wanted: str, lines: list[str]) -> str | None:
    return _line_at(str(len(lines)), wanted, lines) if lines else "program has no lines"


def _pattern(text: str):
    """The pattern compiled by RE2, or a one-line refusal saying what to write instead."""
    try:
        return re2.compile(text, RE2_OPTIONS)
    except re2.error as error:
        reason = error.args[0].decode(errors="replace") if error.args and isinstance(error.args[0], bytes) else error
        raise ExpectationError(f"pattern {text!r} is not a regular expression RE2 runs ({reason}); patterns "
                               "run in linear time, without backreferences or lookaround: rewrite it "
                               "(docs/guide/release-and-golden-tests.md)") from None


def refuse_slow_patterns(expectations) -> None:
    """Every `match:`/`no match:` pattern of a test compiles in RE2, or ExpectationError naming it."""
    for expectation in expectations:
        kind, groups = _text_kind(expectation.strip())
        if kind in ("match", "no match"):
            _pattern(*groups)


def _matches(pattern: str, lines: list[str]) -> str | None:
    compiled = _pattern(pattern)
    return None if any(compiled.search(line) for line in lines) else "no line matches"


def _no_match(pattern: str, lines: list[str]) -> str | None:
    compiled = _pattern(pattern)
    number = next((n for n, line in enumerate(lines, 1) if compiled.search(line)), None)
    return None if number is None else f"line {number} matches: {lines[number - 1]}"


def _stripped(lines: list[str]) -> list[str]:
    return [line.strip() for line in lines]


TEXT_CHECKS: dict[str, Callable[..., str | None]] = {
    "line": _line_present, "no line": _line_absent, "line n": _line_at, "last line": _last_line,
    "match": _matches, "no match": _no_match}


def check_numeric(name: str, expression: str, tolerance: str | None, context: Context) -> str | None:
    """The property against the expression's value, within the tolerance."""
    try:
        property_reader(name)
    except UnknownProperty as error:
        raise ExpectationError(str(error)) from None
    expected = expected_value(expression, context.names)
    reading = read_property(name, context.lines)
    allowed = _tolerance(tolerance, reading)
    value = _shown(expected, reading)
    computed = "" if value == expression.strip() else " = " + value
    shown = f"{name.strip()} = {expression.strip()}{computed} ± {allowed:.3g}"
    if reading is None:
        return f"expected {shown}, program has no {name.strip()}"
    if abs(reading.value - expected) <= allowed:
        return None
    return f"expected {shown}, program has {_shown(reading.value, reading)}{reading.where()}"


def expected_value(expression: str, names: dict) -> float:
    """The expression over the test's names, by the templates' own checked evaluator."""
    from .expressions import compile_expression  # the gate: only what a template expression may be

    try:
        value = evaluate(compile_expression(expression.strip()), names)
    except EngineError as error:
        raise ExpectationError(f"expression {expression.strip()!r}: {error}") from None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ExpectationError(f"expression {expression.strip()!r} gives {value!r}, not a finite number")
    return float(value)


def _tolerance(text: str | None, reading: Reading | None) -> float:
    if text is None:
        return ABSOLUTE_TOLERANCE + (reading.printed_step / 2 if reading is not None else 0.0)
    try:
        value = float(text)
    except ValueError:
        raise ExpectationError(f"tolerance {text!r} is not a number") from None
    if not value >= 0:
        raise ExpectationError(f"tolerance {text!r} must not be negative")
    return value


def _shown(value: float, reading: Reading | None) -> str:
    """A value with the decimals the program printed (6 significant digits if it printed none)."""
    if reading is not None and 0 < reading.printed_step < 1:
        return f"{value:.{round(-math.log10(reading.printed_step))}f}"
    return f"{value:.6g}"


def first_difference(expectations, context: Context) -> str | None:
    """The first expectation the program does not meet, as `expected …`, naming it; None if all hold."""
    for expectation in expectations:
        try:
            problem = check(expectation, context)
        except ExpectationError as error:
            return f"expectation {expectation.strip()!r} fails: {error}"
        if problem is not None:
            return problem if problem.startswith("expected") else f"expected {expectation.strip()!r}: {problem}"
    return None
