"""Where the o-words of a LinuxCNC program lead (docs/reference/linuxcnc-lathe.md §6): each
opening o-word (sub, if, while, do, repeat) paired with its closing one of the same label, the
elseif/else of each if, and the loop each break/continue leaves. A program whose o-words do not
pair is refused before anything runs, naming the line (the control refuses it too). Also the
count of a `repeat` and the rule that a sub is defined before it is called."""
from __future__ import annotations

import msgspec

from ..refusals import Refused
from .linuxcnc_lines import OWord

OPENERS = {"sub": "endsub", "if": "endif", "while": "endwhile", "do": "while", "repeat": "endrepeat"}
LOOPS = frozenset({"while", "do", "repeat"})


class Flow(msgspec.Struct):
    end: dict[int, int] = {}            # opener line -> its closing line
    opener: dict[int, int] = {}         # closing/elseif/else line -> the opener
    branches: dict[int, list[int]] = {}  # if line -> its elseif/else lines
    loop: dict[int, int] = {}           # break/continue/return line -> loop or sub
    subs: dict[str, tuple[int, int]] = {}   # label -> (sub line, endsub line)


class FlowError(Refused):
    def __init__(self, index: int, reason: str) -> None:
        super().__init__(reason)
        self.index = index


def pair(items: list[OWord | str | None]) -> Flow:
    """The o-word structure of the program's lines (index from 0); FlowError names the line."""
    flow, stack = Flow(), list[int]()
    owords = {index: item for index, item in enumerate(items) if isinstance(item, OWord)}
    for index, item in owords.items():
        word = item.keyword
        top = owords[stack[-1]] if stack else None
        if word == "while" and top is not None and top.keyword == "do" and top.label == item.label:
            _close(flow, stack, index, owords)
        elif word in OPENERS:
            if word == "sub" and stack:
                raise FlowError(index, f"o{item.label} sub inside another block: a subroutine is defined at the top")
            stack.append(index)
        elif word in ("elseif", "else"):
            _branch(flow, stack, index, owords)
        elif word in ("endsub", "endif", "endwhile", "endrepeat"):
            _close(flow, stack, index, owords)
        elif word in ("break", "continue", "return"):
            flow.loop[index] = _enclosing(stack, index, owords, "sub" if word == "return" else None)
    if stack:
        first = owords[stack[-1]]
        closing = OPENERS[first.keyword]
        raise FlowError(stack[-1], f"o{first.label} {first.keyword} without its o{first.label} {closing}")
    return flow


def _close(flow: Flow, stack: list[int], index: int, items: dict[int, OWord]) -> None:
    item = items[index]
    if not stack or items[stack[-1]].label != item.label or OPENERS[items[stack[-1]].keyword] != item.keyword:
        raise FlowError(index, f"o{item.label} {item.keyword} closes nothing open under that label")
    opener = stack.pop()
    flow.end[opener], flow.opener[index] = index, opener
    if items[opener].keyword == "sub":
        if item.label in flow.subs:
            raise FlowError(opener, f"o{item.label} sub defined twice")
        flow.subs[item.label] = (opener, index)


def _branch(flow: Flow, stack: list[int], index: int, items: dict[int, OWord]) -> None:
    item = items[index]
    if not stack or items[stack[-1]].keyword != "if" or items[stack[-1]].label != item.label:
        raise FlowError(index, f"o{item.label} {item.keyword} outside an o{item.label} if")
    flow.branches.setdefault(stack[-1], []).append(index)
    flow.opener[index] = stack[-1]


def _enclosing(stack: list[int], index: int, items: dict[int, OWord], kind: str | None) -> int:
    item = items[index]
    for opener in reversed(stack):
        found = items[opener]
        if (kind == "sub" and found.keyword == "sub") or (kind is None and found.keyword in LOOPS
                                                           and found.label == item.label):
            return opener
    raise FlowError(index, f"o{item.label} {item.keyword} outside {'a subroutine' if kind else 'its loop'}")


def repeat_count(value: float) -> int:
    """How often `oN repeat [value]` runs its body: interp_o_word.cc takes
    `round_to_int(settings->test_value)`, which is `(int)std::nearbyint(x)` (interp_internal.hh):
    rounding in the current mode, which nothing in src/ changes (no fesetround) from C's default: nearest
    with ties to even (2.6 -> 3, 2.5 -> 2, 3.5 -> 4, 0.6 -> 1, 0.5 -> 0); 0 or less runs it never.
    Python's round() of a float is the same rule. The value is finite (Values refuses others)."""
    return round(value)


def called_early(label: str, sub_line: int) -> str:
    """The refusal of a call run before the interpreter has passed the sub's definition. o-code.adoc:
    "Subroutines may only be called after they are defined". interp_o_word.cc `control_back_to`
    does not find such a sub in its table of the subs read so far: it first opens a file named
    after the label (cwd, PROGRAM_PREFIX, SUBROUTINE_PATH) and runs that, and only without one skips
    forward in the file to the sub; what runs depends on files the verifier does not have."""
    name = label.strip("<>")
    return (f"o{label} call before its o{label} sub (line {sub_line}) is read: LinuxCNC calls a sub once it "
            f"has read its definition; before that it runs a file {name}.ngc from its SUBROUTINE_PATH if there "
            "is one (o-code.adoc: a sub is defined before it is called); define the sub before the call")
