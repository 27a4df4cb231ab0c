"""The header comments a hobbing program states facts in (`; GEAR n`, `; HOB id`, `; MACHINE
name`, `; FIXTURE id`, `; CYCLE TIME m MIN`, `; ALLOWANCE a MM`): the simulation holds each to the
records, the simulated time and the last cut's depth. A comment that looks like one of them but is written
another way (other case, `GEAR=44`, a trailing comment on a block) would go unchecked while a
reader takes it as the program's claim, so it fails closed: refused unless it is the canonical form."""
from __future__ import annotations

import re
from functools import lru_cache

from ...names import is_safe
from ...nc.lineage import CLASS_NAME, read_lineage

# The words of a header fact, and any time in minutes (a misspelt `; FL00R TO FL00R 9.9 MIN` is
# still read as the program's time by whoever reads it: adversary 29).
CLAIM = re.compile(r"\b(GEAR|HOB|MACHINE|FIXTURE|CYCLE|FLOOR|ALLOWANCE)|\b(CUT|UNIT|n0)\b|[0-9]\s*MIN(UTES?)?\b",
                   re.IGNORECASE)
CANONICAL = (re.compile(r"; GEAR \S+( .*)?"), re.compile(r"; HOB \S+( .*)?"), re.compile(r"; MACHINE \S+"),
             re.compile(r"; FIXTURE \S+"),   # the job's work-holding (engine.simulation.hobbing.holding_facts)
             re.compile(r"; CYCLE TIME [0-9]+(\.[0-9]+)? MIN"), re.compile(r"; FLOOR TO FLOOR [0-9]+(\.[0-9]+)? MIN"),
             re.compile(r"; ALLOWANCE [0-9]+(\.[0-9]+)? MM( .*)?"),
             # the facts engine.simulation.hobbing.header_facts and program_facts hold (issue 26)
             re.compile(r"; n0=[0-9]+ r/min table=[0-9]+(\.[0-9]+)? r/min cuts=[0-9]+ \S+"),
             re.compile(r"; CUT \S+( .*)? X=\S+ \S+"), re.compile(r"; UNIT [0-9]+ z=\S+ b=\S+ Z\S+"))
REMARKS = ("HOB SHIFT PER PART",)     # the templates' note on the shift parameter's line
# The template's version line: a class name may hold a header word (`gear_x`, `hobbed`), but it
# states no header fact; nor does the engine's lineage line (engine.nc.lineage.read_lineage, as
# stored), which the database checked when the program was stored. Only a class name (engine.names)
# is exempt: a template row writes the line, and `; TEMPLATE GEAR=45 v1` states a gear (adversary).
TEMPLATE_VERSION_LINE = re.compile(rf"; TEMPLATE (?:{CLASS_NAME}) v[0-9]+")


def comment_problem(step) -> str | None:
    """A comment naming a header fact must be that header's canonical whole line; a header's
    program name (the verifier's reading: ISO `O1042 (GEAR42)`, which the control shows beside the
    number) must not state one unless it is a program name (adversary: `O1042 (GEAR 45)`)."""
    named = header_name_problem(step.item.name) if step.kind == "header" else None
    return named or line_comment_problem(step.line, step.kind)


@lru_cache(maxsize=4096)
def line_comment_problem(line: str, kind: str) -> str | None:
    """comment_problem of a line read as `kind`. Remembered: a batch's programs share most of
    their comment lines."""
    code, semicolon, comment = line.partition(";")
    if not semicolon or comment.strip() in REMARKS or not CLAIM.search(comment) or _names_a_class(line):
        return None
    if kind == "comment" and not code.strip() and any(form.fullmatch(line) for form in CANONICAL):
        return None
    return ("a comment that names a header fact (gear, hob, machine, fixture, cycle or floor-to-floor time, "
            "allowance, n0, cut, unit) is not its canonical whole-line form `; GEAR <id>`, `; HOB <id>`, "
            "`; MACHINE <name>`, `; FIXTURE <id>`, `; CYCLE TIME <m> MIN`, `; FLOOR TO FLOOR <m> MIN`, "
            "`; ALLOWANCE <mm> MM`, `; n0=<n> r/min table=<n2> r/min cuts=<c> <mode>`, `; CUT <name> … X=<x> <word>`, "
            "`; UNIT <n> z=<z> b=<b> Z<top>`: it would go unchecked")


def header_name_problem(name: str | None) -> str | None:
    """A header's program name that states a header fact and is no program name."""
    if name is None or not CLAIM.search(name) or is_safe("program", name):
        return None
    return (f"the header's program name {name!r} names a header fact (gear, hob, machine, "
            "fixture, cycle or floor-to-floor time, allowance, n0, cut, unit) and is no program name (letters, "
            "digits and _): it would go unchecked; state the fact in its canonical comment line")


def _names_a_class(line: str) -> bool:
    """The template's version line or the lineage line, each whole and exactly as written."""
    return TEMPLATE_VERSION_LINE.fullmatch(line) is not None or read_lineage(line) is not None


def header_place_problem(fact: str, stated_before: bool, moved: bool) -> str | None:
    """A header fact is stated once, in the header block before the first motion: a second or a
    late one leaves the reader two claims or one the machine has already passed."""
    if stated_before:
        return f"a second `; {fact}` line: the header states it once"
    if moved:
        return f"`; {fact}` after the first motion block: it belongs to the header, before any motion"
    return None
