"""Whether a draft changes a stored job's program, the draft made with its own version number
(issue 28 adversary): rows may read template_version, so a draft evaluated with the released
number is not the program the release makes. Its `; TEMPLATE class vN` line then differs from
the released program's in the number alone; that whole-line comment is not a change."""
from __future__ import annotations

import re

from ..nc.lineage import TEMPLATE_LINE

VERSION_WORD = re.compile(r"\bv\d+\b")


def same_program(old: list[str], new: list[str]) -> bool:
    """The lines are equal, but for template lines that differ in their version number alone."""
    return old == new or (len(old) == len(new) and all(a == b or _only_version_differs(a, b)
                                                       for a, b in zip(old, new, strict=True)))


def _only_version_differs(old: str, new: str) -> bool:
    return (_whole_comment(old) and _whole_comment(new) and TEMPLATE_LINE.match(old) is not None
            and TEMPLATE_LINE.match(new) is not None
            and VERSION_WORD.sub("v#", old) == VERSION_WORD.sub("v#", new))


def _whole_comment(line: str) -> bool:
    """A line the control reads as a comment only: `;` to its end (840D, LinuxCNC), or one
    parenthesised comment closing at its end (ISO); a block after it would be run."""
    text = line.strip()
    return text.startswith(";") or (text.startswith("(") and text.endswith(")") and text.count(")") == 1)
