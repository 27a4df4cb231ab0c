"""@-codes: the cutting data written as TEXT/MTEXT on an operation layer (design notes §8).

Seed 000 writes them as `@GROUGH @S100 @F1300 @T01`: an at sign, one letter, the value
without a separator. Here a `:` or `=` after the letter and spaces around it are also
accepted, several codes may share a word (`@GROUGH@S100`) and a decimal comma counts as
a point. Only words that start with `@` are codes, so an e-mail address in a title block
is not one. Each code is parsed by the rule in CODE_RULES; a value outside the rule is an
error naming the layer, the TEXT/MTEXT handle and the text.
"""
from __future__ import annotations

import re
from collections.abc import Callable

import msgspec

from .read import DxfError

OPERATION_KINDS = ("ROUGH", "SLOT", "FINISH", "THREAD", "FACE", "PART")
CODE = re.compile(r"@([A-Za-z])\s*[:=]?\s*([^@\s]*)")
NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)")
TOOL_DIGITS = 4   # a control's T word: T0101 is tool 01 with offset 01 (Fanuc); no turret has 10,000 stations


class CodeRule(msgspec.Struct, frozen=True):
    key: str
    meaning: str
    parse: Callable[[str], object]


def number(text: str) -> float:
    candidate = text if "." in text else text.replace(",", ".", 1)
    if not NUMBER.fullmatch(candidate):
        raise ValueError("must be a number")
    return float(candidate)


def positive(text: str) -> float:
    value = number(text)
    if not value > 0:
        raise ValueError("must be greater than 0")
    return value


def kind(text: str) -> str:
    upper = text.upper()
    if upper not in OPERATION_KINDS:
        raise ValueError(f"must be one of {' | '.join(OPERATION_KINDS)}")
    return upper


def tool(text: str) -> int:
    """A tool number as the drawing writes it, `01`: ASCII digits (str.isdigit() also takes `²`,
    which int() refuses), few enough for a turret's stations (int() refuses over 4,300 digits)."""
    if not (text.isascii() and text.isdigit()) or len(text) > TOOL_DIGITS or int(text) == 0:
        raise ValueError("must be a tool number 1, 2, … (e.g. 01)")
    return int(text)


def coolant(text: str) -> bool:
    if text not in ("8", "08", "9", "09"):
        raise ValueError("must be 8 (coolant on) or 9 (coolant off)")
    return int(text) == 8


def infeed_angle(text: str) -> float:
    value = number(text)
    if not 0 <= value < 90:
        raise ValueError("must be an angle from 0 to below 90 degrees")
    return value


CODE_RULES: dict[str, CodeRule] = {
    "G": CodeRule("kind", "operation type", kind),
    "S": CodeRule("spindle_rpm", "spindle speed r/min", positive),
    "F": CodeRule("feed", "feed", positive),
    "T": CodeRule("tool", "tool number", tool),
    "M": CodeRule("coolant", "coolant M8/M9", coolant),
    "P": CodeRule("thread_pitch", "thread pitch", positive),
    "D": CodeRule("depth_per_pass", "depth per threading pass", positive),
    "A": CodeRule("infeed_angle", "thread infeed angle", infeed_angle),
}


class CodeText(msgspec.Struct, frozen=True):
    """One TEXT/MTEXT of a layer: its handle and plain text."""
    layer: str
    handle: str
    text: str


def codes_in(text: CodeText) -> dict[str, object]:
    """The @-codes of one text as {rule key: value}; DxfError on an unknown or bad code."""
    found: dict[str, object] = {}
    for letter, value in code_matches(text.text):
        rule = CODE_RULES.get(letter.upper())
        if rule is None:
            raise DxfError(f"layer {text.layer!r}, {where(text)}: unknown code @{letter}; known codes "
                           f"are @{' @'.join(CODE_RULES)}")
        merge(found, rule.key, parsed(rule, letter, value, text), text)
    return found


def code_matches(text: str) -> list[tuple[str, str]]:
    """(letter, value) of each code: an @ that starts a word or directly follows a code."""
    matches, last_end = [], None
    for match in CODE.finditer(text):
        start = match.start()
        if start == 0 or text[start - 1].isspace() or start == last_end:
            matches.append((match.group(1), match.group(2)))
            last_end = match.end()
    return matches


def parsed(rule: CodeRule, letter: str, value: str, text: CodeText) -> object:
    try:
        return rule.parse(value)
    except ValueError as reason:
        detail = str(reason)
        raise DxfError(f"layer {text.layer!r}, {where(text)}: bad value {value!r} for @{letter.upper()} "
                       f"({rule.meaning}): {detail}") from None


def merge(codes: dict[str, object], key: str, value: object, text: CodeText) -> None:
    if key in codes and codes[key] != value:
        raise DxfError(f"layer {text.layer!r}, {where(text)}: {key} given twice with different values "
                       f"({codes[key]!r} and {value!r}); keep one")
    codes[key] = value


def layer_codes(texts: list[CodeText]) -> dict[str, object]:
    """All @-codes of one layer's texts; the same code twice must agree."""
    codes: dict[str, object] = {}
    for text in texts:
        for key, value in codes_in(text).items():
            merge(codes, key, value, text)
    return codes


def where(text: CodeText) -> str:
    shown = text.text if len(text.text) <= 60 else text.text[:57] + "…"
    return f"handle {text.handle}, text {shown!r}"
