"""The rows of an imported program (engine.library.nc_import): each line's `o`, written out or
as an f-string whose fields are the job's parameters, spelled as the line spells its numbers
(the exact-spelling rules are in nc_import's docstring). A number becomes a parameter only at an
address the parameter binds (engine.library.nc_params); an equal number elsewhere is left as
written and reported, since the G71 allowance `U0.01` is not the feed `F0.010`."""
from __future__ import annotations

import math
from collections import Counter
from decimal import Decimal, InvalidOperation

import msgspec
from msgspec.structs import replace

from ..errors import EngineError
from ..nc.tokens import NUMBER, WORD, LineFacts, facts, tokenise
from ..templates.evaluator import evaluate
from ..templates.expressions import MAX_EXPRESSION_LENGTH, compile_expression
from ..templates.functions import NC_NUMBER_SPEC
from ..templates.nc_number import style_of
from .nc_params import FUNCTION_ADDRESSES, Binding
from .nc_references import CODE_NAMES, block_context, reference_at


def values_of(bindings: dict[str, Binding]) -> dict:
    """Decimal value → [Binding] of the numeric parameters, in the order given."""
    values: dict = {}
    for binding in bindings.values():
        value = binding.value
        if isinstance(value, bool) or not isinstance(value, (int, float, Decimal)):
            continue
        if isinstance(value, float) and not math.isfinite(value):
            continue
        values.setdefault(Decimal(str(value)), []).append(binding)
    return values


class LeftAlone(msgspec.Struct, frozen=True):
    """A number equal to a parameter's value that it does not bind, and why (`Q100 names the
    contour …`, `F400: feed binds only F`)."""
    line: int
    word: str
    parameter: str
    why: str


class Found(msgspec.Struct):
    """What the lines read so far gave: the references made, the values two parameters binding
    the same address share (the first is used), the words bound per (parameter, address), and
    the equal numbers left alone, in line order."""
    parameterised: int = 0
    ambiguous: dict = {}
    bound: Counter = msgspec.field(default_factory=Counter)
    left_alone: list = []
    bound_lines: dict = {}   # (parameter, address) → lines of the words bound
    left_lines: dict = {}    # (parameter, address) → lines of the equal words left

    def add(self, later: Found) -> None:
        """Take in what the lines after these gave."""
        self.parameterised += later.parameterised
        for value, names in later.ambiguous.items():
            self.ambiguous.setdefault(value, names)
        self.bound.update(later.bound)
        self.left_alone.extend(later.left_alone)
        for mine, theirs in ((self.bound_lines, later.bound_lines), (self.left_lines, later.left_lines)):
            for key, lines in theirs.items():
                mine.setdefault(key, []).extend(lines)

    def add_line(self, line_found: Found, line: int) -> None:
        """Take in what one line gave (engine.library.nc_import reads each distinct text once), as
        if it had been read at `line`: the same references and reports, with that line's number."""
        self.parameterised += line_found.parameterised
        self.ambiguous.update(line_found.ambiguous)   # as _part sets them: the last line read wins
        self.bound.update(line_found.bound)
        self.left_alone.extend(replace(left, line=line) for left in line_found.left_alone)
        for mine, theirs in ((self.bound_lines, line_found.bound_lines), (self.left_lines, line_found.left_lines)):
            for key, lines in theirs.items():
                mine.setdefault(key, []).extend([line] * len(lines))

    def was_bound(self, name: str, address: str | None, line: int) -> None:
        self.bound[(name, address)] += 1
        self.bound_lines.setdefault((name, address), []).append(line)


EMPTY = Found()   # what a line with no number equal to a parameter gives


def number_field(name: str, spelling: str) -> str:
    """The f-string replacement field that prints `name` exactly, in the style of `spelling`
    (engine.templates.nc_number: the value's own digits, at least the file's decimals, never
    rounded to them)."""
    return f"{{{name}:{NC_NUMBER_SPEC}{style_of(spelling)}}}"


class Builder:
    """The `o` of each line, and what the lines read so far gave (`found`)."""

    def __init__(self, bindings: dict[str, Binding], path):
        self.values, self.path = values_of(bindings), path
        self.found = Found()
        self.spelled: dict[tuple, bool] = {}   # (field, name, number) -> the field gives the number back
        # the codes and words of the line being read, once a number needs them
        self.context: frozenset[str] | None = None
        self.line_facts: LineFacts | None = None   # the facts of the line being read, if known

    def read(self, line_number: int, line: str) -> tuple:
        """(facts, o, what the line gave: None for nothing) of one line, read as line
        `line_number`; `found` is left as it was."""
        found, self.found = self.found, Found()
        try:
            tokens = tokenise(line)
            line_facts = facts(tokens)
            o = self.o(line_number, line, tokens, line_facts)
            return line_facts, o, None if self.found == EMPTY else self.found
        finally:
            self.found = found

    def o(self, line_number: int, line: str, tokens, line_facts: LineFacts | None = None) -> str:
        """The row's `o`: the line written out, or an f-string with its references."""
        self.context, self.line_facts = None, line_facts
        parts = [self._part(line_number, tokens, index) for index in range(len(tokens))]
        fields = "".join(text for is_field, text in parts if is_field)
        literal = "".join(text for is_field, text in parts if not is_field)
        quote = "'" if '"' in literal and "'" not in literal + fields else '"'
        if fields:
            body = "".join(text if is_field else _escaped(text, quote, braces=True) for is_field, text in parts)
            o = f"f{quote}{body}{quote}"
        else:
            o = f"{quote}{_escaped(line, quote, braces=False)}{quote}"
        if len(o) > MAX_EXPRESSION_LENGTH:
            raise EngineError(f"{self.path} line {line_number}: {len(line)} characters, more than a "
                              f"template row holds ({MAX_EXPRESSION_LENGTH}); split the line")
        self.found.parameterised += sum(1 for is_field, _ in parts if is_field)
        return o

    def _part(self, line_number: int, tokens, index: int) -> tuple[bool, str]:
        """(True, replacement field) for a number that becomes a reference, else (False, text)."""
        token = tokens[index]
        if token.kind != NUMBER or _is_negative_zero(token.text):
            return False, token.text
        equal = self.values.get(Decimal(token.text), ())
        if not equal:
            return False, token.text
        binding = self._binding(line_number, tokens, index, equal)
        if not binding:
            return False, token.text
        source = number_field(binding[0].name, token.text)
        if not self._spelled(source, binding[0], token.text):
            return False, token.text
        if len(binding) > 1:
            self.found.ambiguous[str(Decimal(token.text))] = [candidate.name for candidate in binding]
        self.found.was_bound(binding[0].name, token.address, line_number)
        return True, source

    def _binding(self, line_number: int, tokens, index: int, equal) -> list:
        """The parameters of the number's value that bind it (nc_params; a reference, that names
        something, only by a bound form naming its address: nc_references); the others are left
        alone, and told why."""
        reference = self._reference(tokens, index)
        address = tokens[index].address
        binding = [] if reference is not None and reference.never else [
            candidate for candidate in equal if candidate.binds(address) and (
                reference is None or (reference.address and candidate.addresses is not None))]
        if reference is not None and reference.target and binding:
            raise EngineError(f"{self.path} line {line_number}: {_word(tokens, index)} names {reference.names}, "
                              f"which no parameter may change ({binding[0].name} binds {address}); take {address} "
                              f"out of its addresses")
        self._leave_alone(line_number, tokens, index, [c for c in equal if c not in binding], reference)
        return binding

    def _reference(self, tokens, index: int):
        if self.context is None:
            self.context = block_context(self.line_facts or facts(tokens))
        return reference_at(tokens, index, self.context)

    def _spelled(self, source: str, binding: Binding, spelling: str) -> bool:
        """Whether the field gives the number back as written (evaluated once per spelling)."""
        key = (source, binding.name, spelling)   # the value is the parameter's, one per name
        if key not in self.spelled:
            try:
                self.spelled[key] = _evaluate(source, binding.name, binding.value) == spelling
            except EngineError:   # more digits than an NC word holds: the file's own number stays
                self.spelled[key] = False
        return self.spelled[key]

    def _leave_alone(self, line_number: int, tokens, index: int, equal, reference) -> None:
        """Report the number to each parameter it equals (a function's number is no quantity)."""
        if equal and (tokens[index].address or "") not in FUNCTION_ADDRESSES:
            word = _word(tokens, index)
            self.found.left_alone.extend(LeftAlone(line_number, word, binding.name, _why(
                word, tokens[index].address, binding, reference)) for binding in equal)
            for binding in equal:
                self.found.left_lines.setdefault((binding.name, tokens[index].address), []).append(line_number)


def _why(word: str, address: str | None, binding: Binding, reference) -> str:
    """Why `binding` leaves the number alone: what it names, or the addresses it binds."""
    if reference is not None:
        return f"{word} names {reference.names}"
    if address in CODE_NAMES and binding.addresses is None:
        return f"{word} names {CODE_NAMES[address]}"
    return f"{binding.name} binds only {binding.described()}"


def _word(tokens, index: int) -> str:
    """The word a number is the value of, as written (`R0.3`, `A=-1.763`); the number alone
    after no address."""
    number = tokens[index]
    for start in range(index - 1, max(index - 5, -1), -1):
        if tokens[start].kind == WORD and tokens[start].text.upper() == number.address:
            return "".join(token.text for token in tokens[start:index + 1])
    return number.text


def _is_negative_zero(spelling: str) -> bool:
    try:
        return spelling.startswith("-") and Decimal(spelling) == 0
    except InvalidOperation:
        return False


def _evaluate(source: str, name: str, value) -> str:
    return evaluate(compile_expression(f'f"{source}"'), {name: value})


def _escaped(text: str, quote: str, braces: bool) -> str:
    if text.isprintable() and "\\" not in text and quote not in text and not (braces and ("{" in text or "}" in text)):
        return text   # most of a line: nothing to escape
    out = []
    for character in text:
        if character in ("\\", quote):
            out.append("\\" + character)
        elif braces and character in "{}":
            out.append(character * 2)
        elif character.isprintable():
            out.append(character)
        else:
            out.append(repr(character)[1:-1])
    return "".join(out)

