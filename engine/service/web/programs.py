"""The programs: a list with the filters of `engine programs list`, a program's page (`engine
programs show`: its record, its status as the check computes it while the page is shown, its
text with the lineage line, each line leading to why it is there; for a MATCH its plot and
simulation), and the look-up an operator needs at the control: the hash on the lineage line (or
the program id) read off the control's screen leads to the program."""
from __future__ import annotations

from starlette.requests import Request
from starlette.responses import RedirectResponse
from starlette.routing import Route

from ...db.origin import this_plant
from ...errors import EngineError
from ...nc.lineage import DRY_RUN_ID, LineageRecord, lineage_shaped, read_lineage
from ...programs.lookup import MIN_HASH_DIGITS, checked_prefix, find_programs, list_programs, programs_with_hash
from ...programs.rendering import MATCH, REFUSED
from .answers import BIGINT_MAX, BadRequest, answered, digits, query_day, query_flag, query_id, query_text, shown, whole
from .pages import wants_json
from .program_views import plot_svg, simulation_report, traced

KINDS = {"draft": True, "released": False}   # the list's --draft / --released
QUERY_SHOWN = 200   # characters of a look-up's query a refusal repeats


def programs(request: Request):
    """`engine programs list [--class C] [--gear ID] [--plant N] [--job ID] [--draft|--released] [--since D]
    [--until D] [--check] --json`; kind=draft|released."""
    def work(conn):
        kind = query_text(request, "kind")
        if kind is not None and kind not in KINDS:
            raise BadRequest(f"kind {kind[:40]!r}: give draft or released (or leave it out for both)")
        found = list_programs(conn, query_text(request, "class"), query_id(request, "gear", "gear"),
                              query_id(request, "job", "job"), KINDS.get(kind or ""),
                              query_day(request, "since"), query_day(request, "until"), query_flag(request, "check"),
                              query_id(request, "plant", "plant"))
        return shown(request, "programs.html", {"programs": found}, lambda: {"here": this_plant(conn)})
    return answered(request, work)


def program(request: Request):
    """`engine programs show ID --json`; the page adds its lines' trace, its plot and simulation."""
    def work(conn):
        record = find_programs(conn, whole("program", request.path_params["program_id"]))[0]
        return shown(request, "program.html", {"programs": [record.as_dict()]}, lambda: _evidence(conn, record))
    return answered(request, work)


def _evidence(conn, record) -> dict:
    """What the page shows of a program beyond its record: only of a MATCH, its lines each with
    the row that made it, its plot and its simulation; of a REFUSED its simulation (what the proof
    refuses); of anything else, why none of it is shown (its lines are not evidence)."""
    status = record.rendering.status
    evidence = {"record": record, "lines": [{"text": line, "row": None, "why": None} for line in record.lines],
                "plot": None, "plot_refusal": None, "simulation": None, "refusal": None}
    if status == MATCH:
        evidence["lines"] = traced(conn, record)
        evidence["plot"], evidence["plot_refusal"] = plot_svg(conn, record.id)
    else:
        evidence["refusal"] = (f"program {record.id}: {status}: {record.rendering.reason}; its plot, trace"
                               + (" and simulation are" if status != REFUSED else " are") + " not shown")
    if status in (MATCH, REFUSED):
        evidence["simulation"] = simulation_report(conn, record.id, record.rendering)
    return evidence


def lookup(request: Request):
    """A program id, the hash on its lineage line (`engine programs show ID | --hash H`) or the whole
    line as read off the control (its id, checked against the line's hashes): one program leads to
    its page, several are listed, anything else is refused in one line."""
    def work(conn):
        typed = query_text(request, "q") or ""
        line = pasted_lineage(typed)
        found = find_programs(conn, int(line.program_id)) if line else find_programs(conn, *_wanted(conn, typed))
        if line:
            _agrees(conn, line, found[0])
        if len(found) == 1 and not wants_json(request):
            return RedirectResponse(f"/programs/{found[0].id}", status_code=303)
        return shown(request, "lookup.html", {"programs": [record.as_dict() for record in found]},
                     lambda: {"records": found, "asked": request.query_params.get("q", "")})
    return answered(request, work)


def _wanted(conn, text: str) -> tuple[int | None, str | None]:
    """(program id, None) for fewer than MIN_HASH_DIGITS digits, or for the id of a stored program
    (a plant's ids have 11 digits or more: issue 33), (None, hash prefix) otherwise. No id is written
    with a leading zero: `00000812` is a hash's first digits, never program 812."""
    typed = text.strip()
    if digits(typed) and (len(typed) < MIN_HASH_DIGITS or _is_program(conn, typed)):
        return whole("program", typed), None
    try:
        return None, checked_prefix(typed)
    except EngineError:
        raise BadRequest(f"{_shown(typed)}: give a program id, {MIN_HASH_DIGITS} or more hex digits of the hash on "
                         "the program's lineage line, or the whole line (`; PROGRAM <id> TEMPLATE <class> v<n> "
                         "<hash8> INPUT <hash8>`)") from None


def pasted_lineage(text: str) -> LineageRecord | None:
    """The lineage line pasted whole (engine.nc.lineage.read_lineage's pasted form: either comment
    form, a block number before it, any case), or None for anything that does not read as one;
    BadRequest for a line that reads as one but is not a stored program's whole line."""
    typed = text.strip()
    if not lineage_shaped(typed):
        return None
    line = read_lineage(typed, pasted=True)
    if line is not None and line.program_id == DRY_RUN_ID:
        raise BadRequest(f"{_shown(typed)} is a dry run's lineage line: a dry run stores no program, so no record "
                         "has it; paste the line of a stored program's file, or its INPUT hash alone")
    if line is None:
        raise BadRequest(f"{_shown(typed)} reads as a lineage line but not a whole one: paste it whole "
                         "(`; PROGRAM <id> TEMPLATE <class> v<n> <hash8> INPUT <hash8>`), or its INPUT hash alone")
    return line._replace(program_id=whole("program", str(line.program_id)))


def _agrees(conn, line: LineageRecord, record) -> None:
    """The line's class (any case: a class name is lower case), version, hashes and DRAFT and
    UNVERIFIED words are its program's; else BadRequest naming the programs they are (a line copied
    from another program's file, or mistyped or changed, must not lead to this one)."""
    said = _said(line.gear_class.lower(), line.version, line.template_hash, line.input_hash, line.draft,
                 line.unverified)
    stored = _said(record.gear_class, record.template_version, record.template_hash[:8],
                   (record.input_hash or "")[:8], record.draft, record.unverified)
    if said == stored:
        return
    raise BadRequest(f"the lineage line names program {line.program_id}, but its TEMPLATE {said} is not program "
                     f"{record.id}'s ({stored}){_theirs(conn, line)}: it is another program's line, or was "
                     "changed; look up its INPUT hash alone")


def _said(gear_class: str, version: int, template_hash: str, input_hash: str, draft: bool, unverified: bool) -> str:
    """What a lineage line says after TEMPLATE (`spur v14 176b5437 INPUT bdf26401 DRAFT`; INPUT - without one)."""
    return (f"{gear_class} v{version} {template_hash} INPUT {input_hash or '-'}" + (" DRAFT" if draft else "")
            + (" UNVERIFIED" if unverified else ""))


def _theirs(conn, line: LineageRecord) -> str:
    """'; they are program 815's' when stored programs carry the line's two hashes."""
    try:
        found = [record.id for record in programs_with_hash(conn, line.input_hash)
                 if record.template_hash.startswith(line.template_hash)] if line.input_hash else []
    except EngineError:
        found = []
    return f"; its hashes are those of program {', '.join(map(str, found[:5]))}" if found else ""


def _shown(typed: str) -> str:
    """The query as typed, whole up to QUERY_SHOWN characters (a lineage line is about 60), quoted."""
    return repr(typed if len(typed) <= QUERY_SHOWN else typed[:QUERY_SHOWN] + "…")


def _is_program(conn, typed: str) -> bool:
    """Digits as an id is written (no leading zero, no more digits than a bigint) naming a stored program."""
    if typed.startswith("0") or len(typed) > len(str(BIGINT_MAX)):
        return False
    number = int(typed)
    found = number <= BIGINT_MAX and conn.execute("SELECT 1 FROM program WHERE id = %s", (number,)).fetchone()
    return bool(found)


ROUTES = [Route("/programs", programs, name="programs"), Route("/programs/{program_id}", program, name="program"),
          Route("/lookup", lookup, name="lookup")]
