"""The work-holding a hobbing program states (`; FIXTURE <id>`, issue 29), held to the one the
simulation proves it against: a job clamped on a work-holding of the library states it once, in the
header, by the library's id; a job on the machine record's fixture and tailstock states none. A
setter reads the line to clamp the gear; a wrong or missing line would clamp it on a part the
hob was never proved to clear."""
from __future__ import annotations

import re
from collections.abc import Iterator

from ...machines.work_holding import WorkHolding
from .headers import header_place_problem

FIXTURE_LINE = re.compile(r"; FIXTURE (\S+)")


def holding_facts(steps, holding: WorkHolding | None, machine: str) -> Iterator[tuple]:
    """(step, message, refuses) for every `; FIXTURE` line that is not the proved work-holding's,
    for the line missing when the job has one, and for a work-holding made for another machine."""
    if holding is not None and holding.machine not in (None, machine):
        yield steps[0], (f"{holding.kind} {holding.id} fits machine {holding.machine}, not {machine} "
                         "(work-holding record)"), True
    stated, moved = None, False
    for step in steps:
        moved = moved or (step.kind == "block" and step.item.moves and step.item.area is None)
        found = FIXTURE_LINE.fullmatch(step.line) if step.kind == "comment" else None
        if found is None:
            continue
        problem = header_place_problem("FIXTURE", stated is not None, moved) or _named_problem(found.group(1), holding)
        if problem:
            yield step, problem, True
        stated = stated or step
    if holding is not None and stated is None:
        yield steps[0], (f"the program does not state its work-holding: the job is clamped on {holding.kind} "
                         f"{holding.id}, which the header states as `; FIXTURE {holding.id}`"), True


def _named_problem(named: str, holding: WorkHolding | None) -> str | None:
    if holding is None:
        return (f"the header names work-holding {named}; the program is proved against the machine record's "
                "fixture and tailstock (its job names no work-holding)")
    if named != holding.id:
        return (f"the header names work-holding {named}; the program is proved against {holding.kind} "
                f"{holding.id} (the job's work-holding)")
    return None
