"""The rows of an imported program (engine.library.nc_import): each line's `o`, written out or
as an f-string whose fields are the job's parameters, spelled as the line spells its numbers
(the exact-spelling rules are in nc_import's docstring)."""
from __future__ import annotations

import math
import re
from decimal import Decimal, InvalidOperation

from ..errors import EngineError
from ..templates.evaluator import evaluate
from ..templates.expressions import MAX_EXPRESSION_LENGTH, compile_expression
from .nc_tokens import NUMBER

CODE_ADDRESSES = frozenset({"G", "M", "$"})   # their numbers name a function, not a value


def values_of(params: dict) -> dict:
    """Decimal value → [(name, value)] of the numeric parameters, in the order given."""
    values: dict = {}
    for name, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, Decimal)):
            continue
        if isinstance(value, float) and not math.isfinite(value):
            continue
        values.setdefault(Decimal(str(value)), []).append((name, value))
    return values


_SPELLING = re.compile(r"([+-]?)([0-9]*)(\.?)([0-9]*)")


def number_field(name: str, spelling: str) -> str:
    """The f-string replacement field that prints `name` in the style of `spelling`."""
    sign, integer, point, fraction = _SPELLING.fullmatch(spelling).groups()
    digits = len(fraction)
    if not integer:
        scale = 10 ** digits
        positive = "'+'" if sign == "+" else "''"
        magnitude = f"round(abs({name}) * {scale})"
        return (f"{{'-' if {name} < 0 else {positive}}}{{{magnitude} // {scale} or ''}}."
                f"{{{magnitude} % {scale}:0{digits}d}}")
    trailing_point = bool(point) and not fraction
    width = len(spelling) - trailing_point
    padding = f"0{width}" if len(integer) > 1 and integer.startswith("0") else ""
    return f"{{{name}:{'+' if sign == '+' else ''}{padding}.{digits}f}}" + ("." if trailing_point else "")


class Builder:
    """The `o` of each line, and the references made and the values found ambiguous so far."""

    def __init__(self, values: dict, path):
        self.values, self.path = values, path
        self.parameterised, self.ambiguous = 0, {}
        self.spelled: dict[tuple, bool] = {}   # (field, name, number) -> the field gives the number back

    def o(self, line_number: int, line: str, tokens) -> str:
        """The row's `o`: the line written out, or an f-string with its references."""
        parts = [self._part(token) for token in tokens]
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
        self.parameterised += sum(1 for is_field, _ in parts if is_field)
        return o

    def _part(self, token) -> tuple[bool, str]:
        """(True, replacement field) for a number that becomes a reference, else (False, text)."""
        if token.kind != NUMBER or token.address in CODE_ADDRESSES or _is_negative_zero(token.text):
            return False, token.text
        candidates = self.values.get(Decimal(token.text))
        if not candidates:
            return False, token.text
        name, value = candidates[0]
        source = number_field(name, token.text)
        key = (source, name, token.text)   # the value is the parameter's, one per name
        if key not in self.spelled:
            self.spelled[key] = _evaluate(source, name, value) == token.text
        if not self.spelled[key]:
            return False, token.text
        if len(candidates) > 1:
            self.ambiguous[str(Decimal(token.text))] = [n for n, _ in candidates]
        return True, source


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

