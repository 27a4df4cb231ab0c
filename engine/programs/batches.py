"""What batches and dry runs share (issue 16).

A batch (`--gears`, `--all`, `--jobs`) plans every gear or job before it stores anything, and a
bad one does not stop the planning: the user learns every bad gear of a night's batch in one run,
each with its one-line reason, instead of one per run. Then the batch stores all programs, or
none if any was bad, unless the caller asks to skip the bad ones (--skip-bad).

A dry run computes and checks exactly as a stored run does (the template, the machine's verifier,
the simulation, the program's name and lines) inside a READ ONLY transaction that is rolled back:
PostgreSQL itself refuses any write in it, nextval() included, so nothing is stored and no
sequence advances. Its program shows the lineage line a stored one carries, but with `DRY-RUN`
where the program id goes: no program id is drawn, and the database's lineage check
(check_program_release) refuses that line, so such a text can never be stored as a program.
"""
from __future__ import annotations

import contextlib
import re
from typing import TYPE_CHECKING

import msgspec
from psycopg.types.json import Jsonb

from ..db.connection import scalar
from ..errors import EngineError
from ..nc.lineage import DRY_RUN_ID
from ..notes import prefixed
from .options import Output, RunMode
from .outputs import files_after_commit
from .records import Planned, Program
from .storage import Batch, Lineage, refuse_unsafe

if TYPE_CHECKING:
    from ..db.connection import Connection

NEW_INPUT_HASH = "SELECT job_input_hash(%s, %s)"   # the hash a new job's parameters would get stored
NOTHING_STORED = re.compile(r"[;,]?\s*nothing stored\s*$")   # said once for the batch, not per gear


class Bad(msgspec.Struct, frozen=True):
    """A gear or job of a batch that cannot be made, with its one-line reason (sent back by
    batch workers in place of its program)."""
    reason: str


def planned_or_bad(what: str, item_id, plan):
    """plan(), or Bad with the reason an EngineError gave, named by `what item_id` ("gear 7")."""
    try:
        return plan()
    except EngineError as error:
        return Bad(reason_of(f"{what} {item_id}", str(error)))


def reason_of(named: str, message: str) -> str:
    message = NOTHING_STORED.sub("", message.strip())
    return message if re.match(rf"{re.escape(named)}\b", message) else f"{named}: {message}"


def checked(planned: Planned) -> Planned:
    """The checks storing makes of a program's name and lines, made while planning, so a batch
    names every program that would be refused."""
    refuse_unsafe(planned.name, planned.lines)
    return planned


class BadBatch(EngineError):
    """Bad gears or jobs in a batch: nothing stored. `problems` lists each (one line each) when
    there are several; one bad item is said in the message alone."""

    def __init__(self, reasons: list[str], total: int, what: str):
        self.problems = reasons if len(reasons) > 1 else []
        self.reasons = reasons
        super().__init__(_bad_batch_message(reasons, total, what))


def _bad_batch_message(reasons: list[str], total: int, what: str) -> str:
    good = total - len(reasons)
    if len(reasons) == 1:
        advice = f"--skip-bad stores the other {good}" if good else f"the one {what} of the batch is bad"
        return f"{reasons[0]}; nothing stored ({advice})"
    if not good:
        return f"every one of the {total} {what}s of the batch is bad, nothing stored:"
    return (f"{len(reasons)} of {total} {what}s of the batch are bad, nothing stored "
            f"(--skip-bad stores the other {good}):")


def good_ones(outcomes: list, what: str, skip_bad: bool) -> tuple[list, tuple[str, ...]]:
    """(the programs to store, the reasons of the bad ones skipped); BadBatch if any is bad and
    they may not be skipped, or if nothing is left to store."""
    bad = [outcome.reason for outcome in outcomes if isinstance(outcome, Bad)]
    good = [outcome for outcome in outcomes if not isinstance(outcome, Bad)]
    if bad and (not skip_bad or not good):
        raise BadBatch(bad, len(outcomes), what)
    return good, tuple(bad)


def dry_batch(encoded: list, skipped: tuple[str, ...]) -> Batch:
    """What the batch would store: programs and lines (each with its lineage line), no ids."""
    return Batch(len(encoded), sum(len(item.lines) + 1 for item in encoded), None, None, None,
                 tuple(prefixed(f"{item.name}: ", note) for item in encoded for note in item.notes), skipped,
                 dry_run=True)


def refuse_out_in_dry_run(output: Output, mode: RunMode) -> None:
    """A file in --out is what an operator loads into the machine and must be a program the
    database holds, byte for byte; a dry run holds none, so it writes no file."""
    if mode.dry_run and output.out is not None:
        raise EngineError("--dry-run stores nothing and writes no file: leave out --out (the program is printed; "
                          "a batch's dry run reports what it would store)")


def refuse_unfit_output(output: Output, mode: RunMode) -> None:
    """No file for a dry run (refuse_out_in_dry_run), nor for a draft's program: a file in --out
    or the machine's output folder is what an operator loads into the machine, and a draft is an
    editor trying a change the release gate has not passed (issue 26); the only mark a draft's
    program carries is ` DRAFT` at the end of its lineage comment."""
    refuse_out_in_dry_run(output, mode)
    if mode.draft and output.out is not None:
        raise EngineError(f"--draft programs are never written to a file for the machine (--out or the config "
                          f"file's output folder, here {output.out}): try the draft with --dry-run (printed, "
                          "nothing stored), or release it (`engine template release --class C`) and instantiate "
                          "the release; nothing stored")


def batch_stage(conn, output: Output, mode: RunMode):
    """The one transaction of a batch: for a dry run READ ONLY and rolled back (its block gets
    None), else one that commits for real and then writes the files (its block gets ProgramFiles).
    A dry run or a draft with a file to write is refused first."""
    refuse_unfit_output(output, mode)
    return read_only(conn) if mode.dry_run else files_after_commit(conn, output, batch=True)


@contextlib.contextmanager
def read_only(conn: Connection):
    """A transaction in which PostgreSQL refuses every write (nextval() too), rolled back at the
    end; inside a caller's transaction a savepoint, rolled back the same way."""
    with conn.transaction(force_rollback=True):
        conn.execute("SET TRANSACTION READ ONLY")
        yield


def dry_program(conn: Connection, planned: Planned, job_id: int | None) -> Program:
    """The program as it would be stored (checked like a stored one), its lineage line saying
    DRY-RUN for the program id; the job id of a stored job made again, else None (no job)."""
    checked(planned)
    template = planned.template
    hashes = {} if job_id is not None else \
        {None: scalar(conn.execute(NEW_INPUT_HASH, (Jsonb(planned.params), Jsonb(planned.module_params))))}
    lineage = Lineage(conn, [planned.machine], [(template.gear_class, template.version)],
                      [job_id] if job_id is not None else [], hashes)
    lines, row_ids = lineage.added(DRY_RUN_ID, job_id, planned.machine, template.gear_class, template.version,
                                   template.hash, planned.result.lines, planned.result.row_ids, planned.unverified)
    return Program(None, job_id, planned.name, lines, planned.gear_class, template.version, template.hash,
                   None, planned.result.trace, row_ids, tuple(planned.notes), planned.layout, planned.unverified)
