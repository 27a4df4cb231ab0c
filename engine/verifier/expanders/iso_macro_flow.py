"""Custom macro B statements of an ISO lathe program followed (issue 27): assignments `#i=…`, the
jumps `GOTO n` and `IF [cond] GOTO n`, `IF [cond] THEN #i=…`, the loops `WHILE [cond] DO m` …
`END m`, and NC blocks whose words hold variables or expressions (`X[#504+6.]`, `Z-#1`), which
become plain words: a dimension rounded to the least input increment (0.001 mm, 0.0001 in), F
as computed, a value in an M, S, T, P … word rounded to a whole number, a G code that must be
whole; ROUND inside a word is refused (the control rounds it to the address's least input
increment there). The loops are paired first (engine.verifier.expanders.iso_loops). Every
statement is one step of the expander's walk, so a loop is bounded by MAX_STEPS like every other
(engine.verifier.expansion). The arithmetic is engine.verifier.expanders.iso_macro."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

from msgspec.structs import replace

import engine.verifier.expanders.iso_loops as iso_loops
import engine.verifier.expanders.iso_macro as macro
from engine.verifier.expanders.iso_macro import MacroError

if TYPE_CHECKING:
    from .iso_lines import Source

ASSIGNMENT = re.compile(r"#\s*(?P<number>\d+|\[.*?\])\s*=(?P<value>.+)", re.DOTALL)
GOTO = re.compile(r"GOTO(?P<target>.+)")
LOOP_END = re.compile(r"END\s*(?P<id>\d+)")
LOOP_DO = re.compile(r"DO\s*(?P<id>\d+)")
LOOP_IDS = (1, 2, 3)
# words whose value is a length (rounded to the least input increment) and those read as whole numbers
DIMENSIONS = frozenset({"X", "Z", "U", "W", "R", "I", "K", "F", "C"})
WHOLE = frozenset({"M", "S", "T", "P", "Q", "L", "D", "H", "E", "A"})


class MacroRun:
    """The program's variables and the loops found so far, over the lines of the file."""

    def __init__(self, sources: list[Source], labels: dict[int, int]) -> None:
        self.sources, self.labels = sources, labels
        self.variables: dict[int, float] = {}
        self.loops = iso_loops.Loops(sources)      # paired before the run: a Fanuc alarms on a bad structure

    def take(self, source: Source, index: int, decimals: int) -> int | Source:
        """The index to go on at after a statement, or the block with its words evaluated."""
        try:
            return self._take(source.macro or "", index, source, decimals)
        except MacroError as error:
            raise source.refuse(str(error)) from None

    def _take(self, code: str, index: int, source: Source, decimals: int) -> int | Source:
        macro.check_brackets(code)
        if code.startswith("#"):
            self._assign(code)
            return index + 1
        if code.startswith("IF"):
            return self._if(code[2:].strip(), index)
        if code.startswith("GOTO"):
            return self._goto(code, index)
        if code.startswith("WHILE"):
            return self._while(code[5:].strip(), index)
        end = LOOP_END.fullmatch(code)
        if end:
            return self.loops.pairs[index]
        if LOOP_DO.fullmatch(code):
            raise MacroError(f"{code}: DO without WHILE loops for ever")
        return replace(source, kind="block", words=block_words(code, self.variables, decimals))

    def _assign(self, code: str) -> None:
        match = ASSIGNMENT.fullmatch(code)
        if match is None:
            raise MacroError(f"{code!r} is not an assignment #i=<expression>")
        target = match["number"]
        number = int(target) if target.isdigit() else macro.variable_number(macro.evaluate(target, self.variables))
        macro.write_variable(self.variables, number, macro.evaluate(match["value"], self.variables))

    def _if(self, code: str, index: int) -> int:
        condition, rest = bracketed(code)
        rest = rest.strip()
        if rest.startswith("THEN"):
            if macro.condition(condition, self.variables):
                self._assign(rest[4:].strip())
            return index + 1
        if not rest.startswith("GOTO"):
            raise MacroError("IF [...] is followed by GOTO n or THEN #i=…")
        return self._goto(rest, index) if macro.condition(condition, self.variables) else index + 1

    def _goto(self, code: str, index: int) -> int:
        match = GOTO.fullmatch(code)
        if match is None:
            raise MacroError(f"{code!r}: GOTO without its sequence number")
        label = int(macro.round_half_away(macro.evaluate(match["target"], self.variables)))
        if label not in self.labels:
            raise MacroError(f"GOTO {label}: there is no block N{label} in this file")
        self.loops.check_jump(index, self.labels[label], label)
        return self.labels[label]

    def _while(self, code: str, index: int) -> int:
        condition, rest = bracketed(code)
        loop = LOOP_DO.fullmatch(rest.strip())
        if loop is None or int(loop["id"]) not in LOOP_IDS:
            raise MacroError("WHILE [...] is followed by DO 1, DO 2 or DO 3")
        if macro.condition(condition, self.variables):
            return index + 1
        return self.loops.pairs[index] + 1


def bracketed(code: str) -> tuple[str, str]:
    """`[a GT [b]] rest` -> ("a GT [b]", " rest"): the first bracket and what follows it."""
    if not code.startswith("["):
        raise MacroError(f"{code!r}: the condition is written in brackets [...]")
    depth = 0
    for at, char in enumerate(code):
        depth += {"[": 1, "]": -1}.get(char, 0)
        if depth == 0:
            return code[1:at], code[at + 1:]
    raise MacroError("a [ without its ]")


NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")
VARIABLE = re.compile(r"#\s*(?:\d+|\[)")


def block_words(code: str, variables: dict[int, float], decimals: int) -> list[tuple[str, str]]:
    """The words of an NC block as the control reads them, a variable or [expression] evaluated."""
    words, at = [], 0
    while at < len(code):
        if code[at].isspace():
            at += 1
            continue
        letter = code[at]
        if not ("A" <= letter <= "Z"):
            raise MacroError(f"{code[at:].split()[0]!r} is not a word (one capital letter and its value)")
        if code[at + 1:].lstrip()[:1] in ("#", "[", "-", "+") and "ROUND" in _word_text(code, at):
            raise MacroError(f"ROUND inside the {letter} word: there it rounds to the least input increment "
                             "of the address (Fanuc), not to a whole number; round in an assignment #i=ROUND[...]")
        value, at = _value(code, at + 1, variables)
        words.append((letter, value if isinstance(value, str) else _written(letter, value, decimals)))
    return words


def _word_text(code: str, at: int) -> str:
    """The text from a word's letter up to the next letter outside brackets (its value)."""
    depth, end = 0, at + 1
    while end < len(code) and (depth or not ("A" <= code[end] <= "Z")):
        depth += {"[": 1, "]": -1}.get(code[end], 0)
        end += 1
    return code[at:end]


def _value(code: str, at: int, variables: dict[int, float]) -> tuple[str | float, int]:
    """A word's value: a plain number as written, or a variable or [expression] evaluated."""
    sign = 1.0
    if code[at:at + 1] in ("-", "+") and code[at + 1:at + 2] in ("#", "["):
        sign, at = (-1.0 if code[at] == "-" else 1.0), at + 1
    if code[at:at + 1] == "[":
        inner, _ = bracketed(code[at:])
        return sign * macro.evaluate(inner, variables), at + len(inner) + 2
    if VARIABLE.match(code, at):
        end = at + 1 + len(code[at + 1:]) - len(code[at + 1:].lstrip())
        if code[end:end + 1] == "[":
            inner, _ = bracketed(code[end:])
            end += len(inner) + 2
        else:
            end += len(re.match(r"\d+", code[end:]).group())   # type: ignore[union-attr]
        return sign * macro.evaluate(code[at:end], variables), end
    number = NUMBER.match(code, at)
    if number is None:
        raise MacroError(f"{code[at - 1:].split()[0]!r}: a letter without its value")
    return number.group(), number.end()


def _written(letter: str, value: float, decimals: int) -> str:
    if letter == "G":
        if value != int(value):
            raise MacroError(f"G{value:g}: a G code from an expression must be whole")
        return str(int(value))
    if letter in WHOLE or letter not in DIMENSIONS:
        return str(int(macro.round_half_away(value)))
    if letter == "F":      # a feed keeps its digits (0.0005 mm/rev is not 0)
        return f"{value:.6f}".rstrip("0")
    text = f"{round(value, decimals):.{decimals}f}"
    return "0." if float(text) == 0 else text
