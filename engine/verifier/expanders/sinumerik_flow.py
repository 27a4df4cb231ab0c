"""Where an 840D program goes next (reference sinumerik-lathe §S4, §S5): jumps to a label or block number
(GOTOF forward, GOTOB backward, each to the nearest target in its direction; GOTO either way and
GOTOC without an alarm when missing, both refused for a target that stands twice),
IF … GOTO…, the structured IF/ELSE/ENDIF, WHILE/ENDWHILE, REPEAT/UNTIL, FOR/ENDFOR, LOOP/ENDLOOP,
and the section repetitions inside the file `REPEAT <label> [<label>] P=n` and `REPEATB <label>
P=n`. The pairs are matched once, before the program runs; a statement without its partner is
refused. A jump to a label the file does not hold is refused (GOTOC too: the control would run
on, but a program that relies on a missing target is not what its writer meant)."""
from __future__ import annotations

import re
from collections.abc import Callable

import msgspec

from ..expansion import ExpansionRefused
from ..refusals import Refused
from .sinumerik_lines import SourceLine

JUMP = re.compile(r"(GOTOF|GOTOB|GOTOC|GOTO) ([A-Z_][A-Z0-9_]*|N\d+|\d+)")
CONDITIONAL_JUMP = re.compile(r"IF(.+?) (GOTOF|GOTOB|GOTOC|GOTO) ([A-Z_][A-Z0-9_]*|N\d+|\d+)")
FOR = re.compile(r"FOR ([A-Z_][A-Z0-9_]*)=(.+) TO (.+)")
SECTION = re.compile(r"(REPEATB|REPEAT) ([A-Z_][A-Z0-9_]*|N\d+)(?: ([A-Z_][A-Z0-9_]*|N\d+))?(?: P=(\d+))?")
PAIRS = {"IF": ("ELSE", "ENDIF"), "WHILE": ("ENDWHILE",), "REPEAT": ("UNTIL",), "FOR": ("ENDFOR",),
         "LOOP": ("ENDLOOP",)}
CLOSERS = {closer: opener for opener, closers in PAIRS.items() for closer in closers}
Condition = Callable[[str], bool]      # evaluates a condition with the program's values
Assign = Callable[[str, str], float]   # assigns a variable the value of an expression ("" only evaluates)
MAX_SECTIONS = 11          # section repetitions nested in one another (the control's call depth)
# where a directed jump searches its target, from the jump's line (reference sinumerik-lathe §S4)
SEARCHES: dict[str, Callable[[int, int], bool]] = {"GOTOF": lambda place, jump: place > jump,
                                                   "GOTOB": lambda place, jump: place <= jump}


class Section(msgspec.Struct):
    start: int       # first line of the section
    end: int         # last line of the section
    back: int        # the line after the REPEAT statement
    left: int        # passes still to run after this one


def _keyword(line: SourceLine) -> str:
    return line.code.split(" ", 1)[0].split("(", 1)[0]


class Flow:
    def __init__(self, lines: list[SourceLine]) -> None:
        self.lines = lines
        self.targets: dict[str, list[int]] = {}       # every line a label or block number stands on
        for index, line in enumerate(lines):
            for target in (line.label, line.block_number):
                if target:
                    self.targets.setdefault(target, []).append(index)
        self.partner: dict[int, int] = {}
        self.opener: dict[int, int] = {}
        self._match_pairs()
        self.sections: list[Section] = []
        self.limits: dict[int, float] = {}

    def _match_pairs(self) -> None:
        stack: list[tuple[str, int]] = []
        for index, line in enumerate(self.lines):
            word = _keyword(line)
            if word == "IF" and JUMP.search(line.code):
                continue
            if word == "REPEAT" and line.code != "REPEAT":
                continue
            if word in PAIRS:
                stack.append((word, index))
            elif word in CLOSERS:
                self._close(stack, word, index, line)
        if stack:
            word, index = stack[-1]
            line = self.lines[index]
            raise ExpansionRefused(line.number, line.text, f"{word} has no {PAIRS[word][-1]}")

    def _close(self, stack: list[tuple[str, int]], word: str, index: int, line: SourceLine) -> None:
        if not stack or stack[-1][0] != CLOSERS[word]:
            raise ExpansionRefused(line.number, line.text, f"{word} closes no {CLOSERS[word]}")
        opener = stack[-1][1]
        self.partner[opener] = index        # IF -> ELSE (then ELSE -> ENDIF) or ENDIF
        self.opener[index] = opener
        if word == "ELSE":
            stack[-1] = ("IF", index)
        else:
            stack.pop()

    def places(self, name: str) -> list[int]:
        key = name if not name.isdigit() else f"N{name}"
        if key not in self.targets:
            raise Refused(f"a jump to {name}, which is not in the file")
        return self.targets[key]

    def target(self, name: str) -> int:
        """The one line of a label or block number; one that stands more than once is refused, since
        which of them the control takes is not confirmed (reference sinumerik-lathe §S4)."""
        places = self.places(name)
        if len(places) > 1:
            lines = ", ".join(str(self.lines[place].number) for place in places)
            raise Refused(f"{name} stands on lines {lines}: which one the control takes here is not confirmed; "
                          "give each block its own number or label")
        return places[0]

    def search(self, jump: str, name: str, index: int) -> int:
        """The line a jump from line `index` reaches: GOTOF searches forward from the jump, GOTOB
        backward (its own block included), GOTO/GOTOC need a target that stands once in the file."""
        if jump not in SEARCHES:
            return self.target(name)
        found = [place for place in self.places(name) if SEARCHES[jump](place, index)]
        if not found:
            direction = "forward" if jump == "GOTOF" else "backward"
            raise Refused(f"{jump} {name}: the label is not {direction} of the jump")
        return found[0] if jump == "GOTOF" else found[-1]

    def control(self, index: int, code: str, condition: Condition,
                assign: Assign) -> int | None | bool:
        """The next line after a control statement (None: the next one), False for no control statement."""
        word = code.split(" ", 1)[0].split("(", 1)[0]
        if word == "IF":
            return self._if(index, code, condition)
        if word.startswith("GOTO"):
            return self._jump(index, code)
        handler = FLOW_HANDLERS.get(word)
        if handler is None:
            return False
        return handler(self, index, code, condition, assign)

    def _jump(self, index: int, code: str) -> int:
        match = JUMP.fullmatch(code)
        if match is None:
            raise Refused(f"{code}: a jump names one label or block number")
        return self.search(match.group(1), match.group(2), index)

    def _if(self, index: int, code: str, condition: Condition) -> int | None:
        match = CONDITIONAL_JUMP.fullmatch(code)
        if match is not None:
            return self._jump(index, f"{match.group(2)} {match.group(3)}") if condition(match.group(1)) else None
        if condition(code[2:].strip()):
            return None
        return self.partner[index] + 1

    def _else(self, index: int, code: str, condition: Condition, assign: Assign) -> int:
        return self.partner[index] + 1            # the IF branch ran: past ENDIF

    def _while(self, index: int, code: str, condition: Condition, assign: Assign) -> int | None:
        return None if condition(code[5:].strip()) else self.partner[index] + 1

    def _back_to_opener(self, index: int, code: str, condition: Condition, assign: Assign) -> int:
        return self.opener[index]

    def _until(self, index: int, code: str, condition: Condition, assign: Assign) -> int | None:
        return None if condition(code[5:].strip()) else self.opener[index] + 1

    def _loop_back(self, index: int, code: str, condition: Condition, assign: Assign) -> int:
        return self.opener[index] + 1

    def _for(self, index: int, code: str, condition: Condition, assign: Assign) -> int | None:
        match = FOR.fullmatch(code)
        if match is None:
            raise Refused(f"{code}: FOR <variable>=<start> TO <end>")
        start = assign(match.group(1), match.group(2))
        self.limits[index] = assign("", match.group(3))
        return None if start <= self.limits[index] else self.partner[index] + 1

    def _endfor(self, index: int, code: str, condition: Condition, assign: Assign) -> int | None:
        opener = self.opener[index]
        match = FOR.fullmatch(self.lines[opener].code)
        assert match is not None      # its FOR was read when the loop began
        value = assign(match.group(1), f"{match.group(1)}+1")
        return opener + 1 if value <= self.limits[opener] else None

    def _ignore(self, index: int, code: str, condition: Condition, assign: Assign) -> None:
        return None

    def _repeat(self, index: int, code: str, condition: Condition, assign: Assign) -> int | None:
        if code == "REPEAT":
            return None
        match = SECTION.fullmatch(code)
        if match is None:
            raise Refused(f"{code}: REPEAT <label> [<label>] P=<n> repeats a section of the file")
        start = self.target(match.group(2))
        # REPEATB <label>: that one block; REPEAT <label>: from it to the line before the REPEAT;
        # REPEAT <label> <label>: from the first to the second (reference sinumerik-lathe §S5)
        end = self.target(match.group(3)) if match.group(3) else (start if match.group(1) == "REPEATB" else index - 1)
        if match.group(1) == "REPEAT" and start > index:
            raise Refused(f"REPEAT {match.group(2)}: the section must stand before the REPEAT (REPEATB searches back)")
        if end < start or len(self.sections) >= MAX_SECTIONS:
            raise Refused(f"{code}: the section ends before it starts, or sections nest deeper than {MAX_SECTIONS}")
        passes = int(match.group(4) or 1)
        if passes < 1:
            return None
        self.sections.append(Section(start, end, index + 1, passes - 1))
        return start

    def after(self, index: int, jump: int | None) -> int:
        """The next line: the jump's, or the next one; at a section's end, its next pass or the line
        after its REPEAT."""
        if jump is not None:
            return jump
        while self.sections and self.sections[-1].end == index:
            section = self.sections[-1]
            if section.left > 0:
                section.left -= 1
                return section.start
            self.sections.pop()
            index = section.back - 1
            return section.back
        return index + 1


FLOW_HANDLERS: dict[str, Callable[..., int | None]] = {
    "ELSE": Flow._else, "ENDIF": Flow._ignore, "WHILE": Flow._while, "ENDWHILE": Flow._back_to_opener,
    "UNTIL": Flow._until, "LOOP": Flow._ignore, "ENDLOOP": Flow._loop_back, "FOR": Flow._for,
    "ENDFOR": Flow._endfor, "REPEAT": Flow._repeat, "REPEATB": Flow._repeat}
