"""The LinuxCNC lathe expander (issue 27, docs/reference/linuxcnc-lathe.md): a bounded
interpreter of the RS274/NGC language as LinuxCNC runs it, turning a program into the plain lines
of the LinuxCNC lathe grammar, each tagged with the line as written.

It follows o-word subroutines defined in the file (`o100 sub … o100 endsub`, `o<name> call [a][b]`,
`return`), loops (`while/endwhile`, `do/while`, `repeat/endrepeat`, `break`, `continue`) and
`if/elseif/else/endif`, numbered and named parameters and expressions (linuxcnc_values), the
modes (linuxcnc_modes) with their save and restore M70–M73 (linuxcnc_context), the motions
(linuxcnc_motion), G76 (linuxcnc_cycles) and G70-G72, whose profile subroutine it reads line by
line for linuxcnc_g7x (`profile`). It stops at M2/
M30 (the control reads nothing after) or at a second `%`. Bounded: more than MAX_STEPS lines run
(a loop that never ends), more than MAX_PLAIN_LINES plain lines, or calls nested deeper than
MAX_CALLS are refused. A call of a subroutine not in the file (an external `o<name>` file
searched in the control's SUBROUTINE_PATH) is refused naming the file: the verifier reads only
the program it is given."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ..expansion import MAX_PLAIN_LINES, MAX_STEPS, ExpansionRefused, PlainLine, register_expander
from ..refusals import Refused
from .linuxcnc_context import Contexts
from .linuxcnc_cycles import move_or_cycle
from .linuxcnc_flow import FlowError, called_early, pair, repeat_count
from .linuxcnc_lines import OWord, read
from .linuxcnc_modes import Executor
from .linuxcnc_params import Frame, Parameters
from .linuxcnc_values import Values
from .linuxcnc_words import Words, read_words

if TYPE_CHECKING:
    from ...machines.records import Machine

MAX_CALLS = 50        # nested subroutine calls followed; LinuxCNC's own limit is of this order


@register_expander("linuxcnc")
def expand_linuxcnc(lines: list[str], machine: Machine) -> list[PlainLine]:
    return Interpreter(lines).run()


class Interpreter:
    def __init__(self, lines: list[str]) -> None:
        self.lines = lines
        self.items = self._read_all(lines)
        try:
            self.flow = pair(self.items)
        except FlowError as error:
            raise ExpansionRefused(error.index + 1, lines[error.index], str(error)) from None
        self.contexts = Contexts()
        self.executor = Executor(move_or_cycle, self.contexts.carry_out)
        self.executor.profile = self.profile
        self.params = Parameters(self.executor.modes)
        self.plain: list[PlainLine] = []
        self.stopped = False
        self.called: set[str] = set()
        self.defined: set[str] = set()      # subs whose definition the run has passed (o-code.adoc)

    def _read_all(self, lines: list[str]) -> list[OWord | str | None]:
        items: list[OWord | str | None] = []
        marks = 0
        for number, line in enumerate(lines, start=1):
            if line.strip() == "%":
                marks += 1
                items.append(None)
                continue
            try:
                items.append(read(line) if marks < 2 else None)
            except Refused as refusal:
                raise ExpansionRefused(number, line, str(refusal)) from None
        return items

    def run(self) -> list[PlainLine]:
        index, steps = 0, 0
        while 0 <= index < len(self.items) and not self.stopped:
            steps += 1
            if steps > MAX_STEPS:
                raise ExpansionRefused(index + 1, self.lines[index], f"more than {MAX_STEPS:,} lines run: a loop "
                                       "that does not end (the control would run it for ever); bound it")
            try:
                index = self._step(index)
            except ExpansionRefused:
                raise
            except Refused as refusal:
                raise ExpansionRefused(index + 1, self.lines[index], str(refusal)) from None
        self._check_end()
        return self.plain

    def _check_end(self) -> None:
        """A file of subroutines that none of its lines call runs nothing; a program without M2/M30
        is refused by LinuxCNC ("file ended with no percent sign or program end")."""
        uncalled = [label for label in self.flow.subs if label not in self.called]
        moved = any(line.text.split()[0] in ("G0", "G1", "G2", "G3", "G33") for line in self.plain)
        if uncalled and not self.called and not moved:
            at = self.flow.subs[uncalled[0]][0]
            raise ExpansionRefused(at + 1, self.lines[at], f"o{uncalled[0]} sub is never called: a subroutine file "
                                   "runs only as called (ngcgui, a lathe macro); verify the program that calls it")
        if not self.stopped:
            last = len(self.lines)
            raise ExpansionRefused(last, self.lines[-1] if self.lines else "", "the program does not end with M2 "
                                   "or M30 (LinuxCNC: file ended with no percent sign or program end)")

    def _step(self, index: int) -> int:
        item = self.items[index]
        if isinstance(item, OWord):
            return OWORDS[item.keyword](self, index, item)
        if item:
            self._words(index, item)
        return index + 1

    def _words(self, index: int, code: str) -> None:
        words = read_words(code, self.params.lookup, self.params.defined)
        self._emit(index, self.executor.run(words))
        if len(self.plain) > MAX_PLAIN_LINES:
            raise Refused(f"the program expands to more than {MAX_PLAIN_LINES:,} blocks; split it")
        for key, value in words.settings:
            self.params.set(key, value)
        self.stopped = words.has_m(2) or words.has_m(30)

    def _emit(self, index: int, texts: list[str]) -> None:
        """Each plain line with the blend tolerance in force (G64 P, mm: the turning simulation's)."""
        blend = self.executor.modes.blend
        self.plain.extend(PlainLine(text, index + 1, self.lines[index], blend) for text in texts)
    def profile(self, label: str, line: Callable[[Words], None]) -> None:
        """The sub `label` read as a G70-G72 reads its profile (LinuxCNC interp_g7x.cc convert_g7x):
        its o-words and parameter settings carried out, each other line's words given to `line`
        and not run; the call's line is the cycle's, so a refusal here names the profile's line."""
        sub = self.flow.subs.get(label)
        if sub is None:
            raise Refused(f"Q{label}: no o{label} sub in this program (the profile a G70-G72 follows)")
        level, index, steps = len(self.params.frames), sub[0] + 1, 0
        self.called.add(label)
        self.params.frames.append(Frame(back=-1))
        self.contexts.enter()       # its endsub leaves a call level, as a call's does
        while len(self.params.frames) > level:
            steps += 1
            if steps > MAX_STEPS:
                raise Refused(f"the profile o{label} runs more than {MAX_STEPS:,} lines: a loop that does not end")
            try:
                index = self._profile_step(index, line)
            except ExpansionRefused:
                raise
            except Refused as refusal:
                raise ExpansionRefused(index + 1, self.lines[index], str(refusal)) from None

    def _profile_step(self, index: int, line: Callable[[Words], None]) -> int:
        item = self.items[index]
        if isinstance(item, OWord):
            return OWORDS[item.keyword](self, index, item)
        if item:
            words = read_words(item, self.params.lookup, self.params.defined, profile=True)
            for key, value in words.settings:
                self.params.set(key, value)
            line(words)
        return index + 1

    def value(self, text: str) -> float:
        reader = Values(text, self.params.lookup, self.params.defined)
        found = reader.expression()
        if reader.at != len(text):
            raise Refused(f"{text[reader.at:reader.at + 12]!r} after the o-word's [ … ]")
        return found

    def arguments(self, text: str) -> list[float]:
        reader, found = Values(text, self.params.lookup, self.params.defined), []
        while reader.at < len(text):
            found.append(reader.expression())
        return found

    # o-words: each returns the index of the next line to run
    def _sub(self, index: int, item: OWord) -> int:
        self.defined.add(item.label)
        return self.flow.end[index] + 1          # a definition: skipped where it stands

    def _call(self, index: int, item: OWord) -> int:
        sub = self.flow.subs.get(item.label)
        if sub is None:
            named = item.label.strip("<>")
            where = f"the file {named}.ngc" if item.label.startswith("<") else f"an o{item.label} sub"
            raise Refused(f"o{item.label} call: {where} is not in this program (an external subroutine "
                          "the control finds on its SUBROUTINE_PATH); put the sub into the file")
        if item.label not in self.defined:
            raise Refused(called_early(item.label, sub[0] + 1))
        if len(self.params.frames) > MAX_CALLS:
            raise Refused(f"more than {MAX_CALLS} nested calls: a recursion that does not end")
        self.called.add(item.label)
        frame = Frame(back=index + 1, numbered=dict(enumerate(self.arguments(item.rest), start=1)))
        self.params.frames.append(frame)
        self.contexts.enter()
        return sub[0] + 1

    def _return(self, index: int, item: OWord) -> int:
        """Back to the caller; an M73 of the sub restores the modes it saved (linuxcnc_context)."""
        if len(self.params.frames) == 1:
            raise Refused(f"o{item.label} {item.keyword} reached without a call")
        self._emit(index, self.contexts.leave(self.executor))
        return self.params.frames.pop().back

    def _if(self, index: int, item: OWord) -> int:
        if self.value(item.rest):
            return index + 1
        for branch in self.flow.branches.get(index, []):
            found = self.items[branch]
            assert isinstance(found, OWord)
            if found.keyword == "else" or self.value(found.rest):
                return branch + 1
        return self.flow.end[index] + 1

    def _branch_end(self, index: int, item: OWord) -> int:
        return self.flow.end[self.flow.opener[index]] + 1     # a branch taken runs into the next one: skip

    def _while(self, index: int, item: OWord) -> int:
        if index in self.flow.opener:                          # the while closing a do
            return self.flow.opener[index] + 1 if self.value(item.rest) else index + 1
        return index + 1 if self.value(item.rest) else self.flow.end[index] + 1

    def _loop_end(self, index: int, item: OWord) -> int:
        opener = self.flow.opener[index]
        if item.keyword == "endwhile":
            return opener
        counts = self.params.frame.counts
        counts[opener] -= 1
        return opener + 1 if counts[opener] > 0 else index + 1

    def _repeat(self, index: int, item: OWord) -> int:
        count = repeat_count(self.value(item.rest))
        self.params.frame.counts[index] = count
        return index + 1 if count > 0 else self.flow.end[index] + 1

    def _break(self, index: int, item: OWord) -> int:
        return self.flow.end[self.flow.loop[index]] + 1

    def _continue(self, index: int, item: OWord) -> int:
        loop = self.flow.loop[index]
        found = self.items[loop]
        assert isinstance(found, OWord)
        return loop if found.keyword == "while" else self.flow.end[loop] if found.keyword == "do" else \
            self._loop_end(self.flow.end[loop], self.items[self.flow.end[loop]])  # type: ignore[arg-type]

    def _next(self, index: int, item: OWord) -> int:
        return index + 1


OWORDS = {"sub": Interpreter._sub, "endsub": Interpreter._return, "return": Interpreter._return,
          "call": Interpreter._call, "if": Interpreter._if, "elseif": Interpreter._branch_end,
          "else": Interpreter._branch_end, "endif": Interpreter._next, "while": Interpreter._while,
          "endwhile": Interpreter._loop_end, "endrepeat": Interpreter._loop_end, "do": Interpreter._next,
          "repeat": Interpreter._repeat, "break": Interpreter._break, "continue": Interpreter._continue}
