"""The 840D lathe program as stored on the control, run by a bounded interpreter into the plain
lines the 840D lathe grammar reads (engine.verifier.expansion, issue 27).

It follows the program the way the control does, line by line from the first: R-parameters and
DEF variables with their arithmetic (engine.verifier.expanders.sinumerik_expressions), the jumps
GOTOF/GOTOB/GOTO/GOTOC to a label or block number, IF … GOTO…, IF/ELSE/ENDIF, WHILE/ENDWHILE,
REPEAT/UNTIL, FOR/ENDFOR, LOOP/ENDLOOP, and the section repetitions REPEAT/REPEATB … P=n, the
subprogram calls inside the file. Every line it runs counts one step; past MAX_STEPS the
program is refused, so a loop that never ends is refused, not followed for ever. Each block
becomes one plain block (engine.verifier.expanders.sinumerik_blocks); a comment line stays a
comment line (text that is not printable ASCII, such as umlauts, is left out of it: the
verifier reads the code, not the comment).

Refused, naming the line and the construct: a vendor cycle (CYCLE95 …: no model of the moves it
makes), a call of a program that is not in the file (L4000, a named subprogram), a system
variable, an indexed parameter, a word the tables do not know. The header `%_N_<name>_MPF` and
the path line `;$PATH=…` are passed on as they are: the grammar holds the name to the
program's own."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

import engine.verifier.expansion as expansion  # read at call time: a test may lower MAX_STEPS

from ..expansion import ExpansionRefused, PlainLine, register_expander
from ..refusals import Refused
from .sinumerik_blocks import BlockState, plain_block
from .sinumerik_expressions import evaluate, names_read, round_half_up
from .sinumerik_flow import Flow
from .sinumerik_lines import SourceLine, Word, check_line_characters, read_source, words

if TYPE_CHECKING:
    from ...machines.records import Machine

HEADER = re.compile(r"%_N_[A-Za-z0-9_]+_(?:MPF|SPF)|;\$PATH=/\S*")
PRINTABLE = re.compile(r"[ -~]*")
# A move already in plain form (the engine's own output, most CAM output): read by one pattern,
# its numbers of at most twelve digits, so a long program is not taken apart word by word.
_NUMBER = r"-?\d{1,6}(?:\.\d{0,6})?"
PLAIN_MOVE = re.compile(rf"G([0-3]) X({_NUMBER}) Z({_NUMBER})(?: CR={_NUMBER})?(?: F{_NUMBER[2:]})?")
VARIABLE_TYPES = {"REAL": float, "INT": int, "BOOL": bool}
DEFINITION = re.compile(r"DEF (REAL|INT|BOOL|CHAR|STRING\[\d+\]|AXIS|FRAME|POS) (.+)")
DEFINED_NAME = re.compile(r"([A-Z_][A-Z0-9_]*)(?:=(.+))?")
R_PARAMETER = re.compile(r"R\d+")
CYCLE = re.compile(r"(?:CYCLE\d+|[A-Z]+_[A-Z0-9_]*|POCKET\d*|SLOT\d*|HOLES\d*|LONGHOLE|CYCLE)\(")
EXTERNAL_CALL = re.compile(r"L\d+(?: P\d+)?|[A-Z_][A-Z0-9_]*(?: P\d+)?")
STATEMENTS_REFUSED = {
    "CASE": "CASE … OF jumps by a value table the expander does not follow; write IF … GOTOF",
    "PROC": "PROC starts a subprogram definition; a main program stored on the control has none",
    "MCALL": "MCALL repeats a cycle after every move; the expander follows no cycle",
    "SAVE": "SAVE belongs to a subprogram definition",
    "EXTERN": "EXTERN declares an external subprogram, which is not in the file",
    "CALL": "CALL runs a program named at run time, which is not in the file",
    "PCALL": "PCALL runs a program by a path, which is not in the file",
    "SETAL": "SETAL raises a cycle alarm on the control",
}


@register_expander("840d-lathe")
def expand_840d_lathe(lines: list[str], machine: Machine) -> list[PlainLine]:
    return Interpreter(lines, machine).run()


class Interpreter:
    """The program's values (R-parameters, DEF variables), its block state and its flow (jumps,
    loops, section repetitions), and the plain lines made so far."""

    def __init__(self, lines: list[str], machine: Machine) -> None:
        self.lines = [_read(number, text) for number, text in enumerate(lines, start=1)]
        self.values: dict[str, float] = {}
        self.types: dict[str, type] = {}
        self.block = BlockState(machine)
        self.flow = Flow(self.lines)
        self.plain: list[PlainLine] = []
        self.ended = False

    def run(self) -> list[PlainLine]:
        index, steps = 0, 0
        while index < len(self.lines) and not self.ended:
            line = self.lines[index]
            steps += 1
            if steps > expansion.MAX_STEPS:
                raise ExpansionRefused(line.number, line.text, f"more than {expansion.MAX_STEPS:,} lines run: a "
                                       "loop that does not end (or ends too late) is refused")
            try:
                index = self.flow.after(index, self._run(index, line))
            except Refused as refusal:
                raise ExpansionRefused(line.number, line.text, str(refusal)) from None
        self._nothing_after(index)
        return self.plain

    def _nothing_after(self, index: int) -> None:
        """After the M30 (M2, M17) that ended the run the control reads nothing: a block written
        there is refused, as in the engine's own programs (comments and labels may stand)."""
        for line in self.lines[index:]:
            if line.code and self.ended:
                raise ExpansionRefused(line.number, line.text, "a line after M30: the program ends there, and the "
                                       "control reads nothing after it")

    def _run(self, index: int, line: SourceLine) -> int | None:
        """Runs one line; the index of the line to run next, or None for the next one."""
        if line.number <= 2 and HEADER.fullmatch(line.text.strip()):
            self._emit(line, line.text.strip())
            return None
        if not line.code:
            self._comment(line)
            return None
        plain_move = PLAIN_MOVE.fullmatch(line.text) if self.block.diameter else None
        if plain_move is not None:
            self._plain_move(line, plain_move)
            return None
        jump = self.flow.control(index, line.code, self._condition, self._assign)
        if jump is not False:
            return jump
        self._statement(line)
        return None

    def _plain_move(self, line: SourceLine, move: re.Match[str]) -> None:
        """A move written as the grammar reads it: passed on as written, its motion and end kept."""
        self.block.motion = int(move.group(1))
        self.block.position.update(X=float(move.group(2)), Z=float(move.group(3)))
        self._emit(line, line.text)

    def _condition(self, text: str) -> bool:
        return bool(evaluate(text, self.values))

    def _assign(self, name: str, text: str) -> float:
        """Evaluates `text` and, when `name` is given (a FOR variable), assigns it."""
        value = evaluate(text, self.values)
        if name:
            if not self._assignable(name):
                raise Refused(f"FOR {name}: the loop variable must be a DEF variable or an R-parameter")
            value = self.values[name] = _typed(self.types.get(name, float), value)
        return value

    def _comment(self, line: SourceLine) -> None:
        if line.comment_only:
            text = line.text.strip()
            self._emit(line, text if PRINTABLE.fullmatch(text) and not text.startswith(";$") else ";")

    def _statement(self, line: SourceLine) -> None:
        code = line.code
        first = code.split(" ", 1)[0].split("(", 1)[0]
        if first in STATEMENTS_REFUSED:
            raise Refused(STATEMENTS_REFUSED[first])
        if code.startswith("DEF "):
            self._define(code)
            return
        if code.startswith("/"):
            raise Refused("a block skipped by the skip switch (/) runs or not as the operator sets it: "
                          "both programs would need verifying")
        self._block(line, words(code))

    def _define(self, code: str) -> None:
        """DEF REAL/INT/BOOL names, each 0 (FALSE) unless given a value (reference sinumerik-lathe §S2)."""
        match = DEFINITION.fullmatch(code)
        if match is None or match.group(1) not in VARIABLE_TYPES:
            raise Refused(f"{code[:40]}: only DEF REAL, INT and BOOL variables are evaluated")
        kind = VARIABLE_TYPES[match.group(1)]
        for item in _split_names(match.group(2)):
            name = DEFINED_NAME.fullmatch(item)
            if name is None:
                raise Refused(f"DEF {item}: an array or a name the expander does not read")
            self.types[name.group(1)] = kind
            self.values[name.group(1)] = _typed(kind, evaluate(name.group(2), self.values) if name.group(2) else 0.0)

    def _block(self, line: SourceLine, found: list[Word]) -> None:
        self._one_reading(found)
        address_words = []
        for word in found:
            if word.form == "equals" and self._assignable(word.name):
                kind = self.types.get(word.name, float)
                self.values[word.name] = _typed(kind, evaluate(word.value, self.values))
            else:
                address_words.append(word)
        _refuse_calls(address_words)
        if not address_words:
            return
        plain = plain_block(address_words, self.block, self.values)
        self.ended = plain.ends
        if plain.text():
            self._emit(line, plain.text())

    def _one_reading(self, found: list[Word]) -> None:
        """A block that assigns a variable and reads it in another word (`G0 X=R1 R1=100`), or assigns
        it twice, is refused: whether the control assigns before it evaluates the other words, or in
        the written order, is not confirmed (reference sinumerik-lathe §S2). `R1=R1+1` reads the old value."""
        assigned = [word.name for word in found if word.form == "equals" and self._assignable(word.name)]
        for word in found:
            if word.form != "equals" or word.value.startswith('"'):
                continue
            others = set(assigned) - ({word.name} if assigned.count(word.name) == 1 else set())
            read = names_read(word.value) & others
            if read or (word.name in assigned and assigned.count(word.name) > 1):
                name = sorted(read)[0] if read else word.name
                raise Refused(f"{name} is assigned in this block and read or assigned again in it ({word.name}="
                              f"{word.value}): the order the control takes them in is not confirmed; assign "
                              "in a block of its own")

    def _assignable(self, name: str) -> bool:
        return name in self.types or bool(R_PARAMETER.fullmatch(name))

    def _emit(self, line: SourceLine, text: str) -> None:
        self.plain.append(PlainLine(text, line.number, line.text))
        if len(self.plain) > expansion.MAX_PLAIN_LINES:
            raise Refused(f"the program expands to more than {expansion.MAX_PLAIN_LINES:,} blocks; split it")


def _read(number: int, text: str) -> SourceLine:
    if not isinstance(text, str):
        raise ExpansionRefused(number, repr(text), f"a line must be text, not {type(text).__name__}")
    if PLAIN_MOVE.fullmatch(text):
        return SourceLine(number, text, None, None, text, False)
    try:
        check_line_characters(text)
        return read_source(number, text)
    except Refused as refusal:
        raise ExpansionRefused(number, text, str(refusal)) from None


def _typed(kind: type, value: float) -> float:
    """INT rounds to a whole number the control's way (half up, as ROUND), BOOL is 1 or 0 (reference
    sinumerik-lathe §S2)."""
    if kind is int:
        return round_half_up(value)
    if kind is bool:
        return float(bool(value))
    return value


def _split_names(text: str) -> list[str]:
    items, depth, current = [], 0, ""
    for character in text:
        depth += {"(": 1, ")": -1}.get(character, 0)
        if character == "," and depth == 0:
            items.append(current.strip())
            current = ""
        else:
            current += character
    return [*items, current.strip()]


def _refuse_calls(found: list[Word]) -> None:
    """A vendor cycle, or a call of a program that is not in the file, is refused by its name."""
    for word in found:
        if word.form == "call" and (word.name.startswith("CYCLE") or CYCLE.match(word.name + "(")):
            raise Refused(f"{word.name} is a vendor cycle without a model here: the moves it makes cannot be "
                          "verified; program its moves (G0/G1/G2/G3) or use the record's templates")
        if word.name == "L" and word.form == "number":
            raise Refused(f"L{word.value} calls an external subprogram that is not in the file; "
                          "put its moves in the program")
        if word.form == "keyword" and word.name not in _KEYWORDS:
            raise Refused(f"{word.name} calls a subprogram that is not in the file (or is a word the "
                          "expander does not know); put its moves in the program")


_KEYWORDS = frozenset({"DIAMON", "DIAMOF", "DIAM90", "SUPA", "FNORM", "SOFT", "BRISK", "STOPRE", "TRAFOOF",
                       "TRANSMIT", "TRACYL", "CFTCP", "CFC", "CFIN", "TRANS", "ATRANS", "ROT", "SCALE", "MIRROR"})
