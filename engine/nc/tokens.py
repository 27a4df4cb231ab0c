"""Tokenising one NC line into units (design notes §5), losslessly.

`detokenise(tokenise(line)) == line` for every string: each rule consumes at least one
character and a token's text is exactly what it consumed. The kinds:

* word    an address or keyword: `G`, `X`, `g`, `EGON`, `IF`, `sub`, `$` (LinuxCNC spindle)
* number  `01`, `250.`, `-.4`, `0.0500`; `address` names the word it belongs to
          (`G01` → address G; `A=-1.763` → address A; in `[2.5 / #<s>]` none)
* param   an NC parameter (variable) reference: `#1`, `#<_x>`, `#<_hal[a.b]>`, and the
          Sinumerik R parameter in `R1=5` and `X=R1+2`
* name    an identifier with digits or underscores: `CYCLE800`, `_X_HOME`, `$AA_IM`
* label   a block label at the start of a block: `N10`, `O100`, `O<turning>`, `MARKE1:`
* comment `; to the end`, `(…)` with nested parentheses (`((…))`), unclosed to the end
* string  `"DRILL 8.5"`
* symbol  `=`, `[`, `]`, `,`, `+`, `%`, … ; `(` and `)` of a call or grouping
* space   blanks, tabs, carriage returns
* text    anything else (EMCO's back-quotes, stray bytes)

`(` opens a comment unless it follows a word or name directly (`EGON(`, `MSG(`) or an
operator (`=(`), where it is Sinumerik's call or grouping parenthesis. A sign belongs to a
number unless it follows a value (number, param, name, string, `]`, `)`) with no blank in
between: `X-170` and `01 -1000` are negative numbers, `#14-#3` and `#13-5` are subtractions.
"""
from __future__ import annotations

import re
from decimal import Decimal

import msgspec

WORD, NUMBER, PARAM, NAME, LABEL = "word", "number", "param", "name", "label"
COMMENT, STRING, SYMBOL, SPACE, TEXT = "comment", "string", "symbol", "space", "text"

AXIS_LETTERS = frozenset("XYZABCUVW")
_VALUE_KINDS = frozenset({NUMBER, PARAM, NAME, STRING})
_OPERATORS = frozenset("=+-*/(,[<>")


class Token(msgspec.Struct, frozen=True):
    kind: str
    text: str
    address: str | None = None   # numbers only: the word (upper case) whose value it is


class _Context(msgspec.Struct):
    tokens: list

    def previous(self) -> Token | None:
        """The last token that is not blank."""
        for token in reversed(self.tokens):
            if token.kind != SPACE:
                return token
        return None

    def spaced(self) -> bool:
        return bool(self.tokens) and self.tokens[-1].kind == SPACE

    def at_block_start(self) -> bool:
        return all(t.kind == SPACE or t.text == "/" for t in self.tokens)

    def after_value(self) -> bool:
        previous = self.previous()
        return previous is not None and (previous.kind in _VALUE_KINDS or previous.text in (")", "]"))

    def in_expression(self) -> bool:
        previous = self.previous()
        return previous is not None and previous.kind == SYMBOL and previous.text in _OPERATORS

    def opens_group(self) -> bool:
        previous = self.previous()
        if previous is None:
            return False
        if previous.kind in (WORD, NAME) and not self.spaced():
            return True
        return self.in_expression()


def _regex(pattern: str, when=None):
    compiled = re.compile(pattern, re.ASCII)

    def match(line: str, position: int, context: _Context) -> int | None:
        found = compiled.match(line, position)
        return found.end() if found and found.end() > position and (when is None or when(context)) else None
    return match


def _paren_comment(line: str, position: int, context: _Context) -> int | None:
    """A `(…)` comment with nested parentheses; unclosed, it runs to the end of the line."""
    if line[position] != "(" or context.opens_group():
        return None
    depth = 0
    for index in range(position, len(line)):
        depth += {"(": 1, ")": -1}.get(line[index], 0)
        if depth == 0:
            return index + 1
    return len(line)


_LETTERS_RUN = re.compile(r"\$?[A-Za-z_]+", re.ASCII)
_NAME_REST = re.compile(r"[A-Za-z0-9_]*", re.ASCII)


def _word_or_name(line: str, position: int, context: _Context) -> tuple[str, int] | None:
    found = _LETTERS_RUN.match(line, position)
    if not found:
        return (WORD, position + 1) if line[position] == "$" else None
    letters, end = found.group(), found.end()
    digits_follow = end < len(line) and line[end] in "0123456789"
    if "_" in letters or letters.startswith("$") or (len(letters) > 1 and digits_follow):
        rest = _NAME_REST.match(line, end)
        assert rest is not None   # [A-Za-z0-9_]* matches the empty text too
        return NAME, rest.end()
    return WORD, end


_NUMBER = r"(?:\d+\.?\d*|\.\d+)"

_LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
_DIGITS = "0123456789"
# (kind, matcher, the characters a match can start with: None for any) tried in order at each
# position; the first that matches wins. A rule that cannot start with the character at the
# position is not tried (the same first match, a third of the time).
RULES = (
    (SPACE, _regex(r"\s+"), " \t\n\r\f\v"),
    (COMMENT, _regex(r";.*"), ";"),
    (COMMENT, _paren_comment, "("),
    (STRING, _regex(r'"[^"]*"?'), '"'),
    (PARAM, _regex(r"#(?:<[^>]*>?|\d+)"), "#"),
    (LABEL, _regex(r"[Nn]\d+|[Oo](?:<[^>]*>?|\d+)|[A-Za-z_]\w*:(?!=)", _Context.at_block_start), _LETTERS + "_"),
    (PARAM, _regex(r"[Rr]\d+(?=\s*=(?!=))"), "Rr"),
    (PARAM, _regex(r"[Rr]\d+", _Context.in_expression), "Rr"),
    (NUMBER, _regex(r"[+-]" + _NUMBER, lambda context: context.spaced() or not context.after_value()), "+-"),
    (NUMBER, _regex(_NUMBER), _DIGITS + "."),
    (None, _word_or_name, _LETTERS + "_$"),
    (SYMBOL, _regex(r"[=\[\](),+\-*/<>:%&|!^~?@{}]"), "=[](),+-*/<>:%&|!^~?@{}"),
    (TEXT, _regex(r".", ), None),
)
_RULES_AT: dict[str, tuple] = {}


def _rules_at(character: str) -> tuple:
    found = _RULES_AT.get(character)
    if found is None:
        found = _RULES_AT[character] = tuple((kind, matcher) for kind, matcher, starts in RULES
                                             if starts is None or character in starts)
    return found


def tokenise(line: str) -> list[Token]:
    """The units of one NC line, in order; their texts concatenate to the line."""
    context = _Context([])
    tokens, position = context.tokens, 0
    while position < len(line):
        kind, end = _next(line, position, context)
        if kind == NUMBER:
            token = Token(kind, line[position:end], _address(tokens))
        elif kind == TEXT and tokens and tokens[-1].kind == TEXT:
            token = Token(TEXT, tokens.pop().text + line[position:end])
        else:
            token = Token(kind, line[position:end])
        tokens.append(token)
        position = end
    return tokens


def _next(line: str, position: int, context: _Context) -> tuple[str, int]:
    for kind, matcher in _rules_at(line[position]):
        found = matcher(line, position, context)
        if found is None:
            continue
        if kind is None:
            return found
        return kind, found
    return TEXT, position + 1   # unreachable: the TEXT rule matches any character but "\n"


def _address(tokens: list) -> str | None:
    """The word a number is the value of: `X-170`, `X #14`, `A=-1.763`, `M1=3`."""
    significant = _last_significant(tokens, 3)
    if significant and significant[0].text == "=":
        significant.pop(0)
        if significant and significant[0].kind == NUMBER and significant[0].address:
            return significant[0].address        # `M1=3`: the value of M's extension
    if significant and significant[0].kind == WORD:
        return significant[0].text.upper()
    return None


def _last_significant(tokens: list, count: int) -> list:
    """The last `count` tokens that are not blank, the last first."""
    found = []
    for token in reversed(tokens):
        if token.kind != SPACE:
            found.append(token)
            if len(found) == count:
                break
    return found


def detokenise(tokens) -> str:
    return "".join(token.text for token in tokens)


class LineFacts(msgspec.Struct, frozen=True):
    """What a line says, for module assignment: codes `G1`/`M8`, words, axes, code or not."""
    codes: frozenset
    words: frozenset
    axes: frozenset
    has_code: bool
    first: Token | None
    labels: tuple


def code_number(text: str) -> str:
    """`01` → `1`, `91.10` → `91.1`: the number of a G or M code as it is meant."""
    return format(Decimal(text).normalize(), "f")


def facts(tokens) -> LineFacts:
    significant = [t for t in tokens if t.kind not in (SPACE, COMMENT)]
    words = frozenset(t.text.upper() for t in significant if t.kind in (WORD, NAME))
    codes = frozenset(t.address + code_number(t.text) for t in significant
                      if t.kind == NUMBER and t.address in ("G", "M"))
    return LineFacts(codes, words, words & AXIS_LETTERS, bool(significant),
                     significant[0] if significant else None,
                     tuple(t.text.upper() for t in significant if t.kind == LABEL))
