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
from ...programs.lookup import MIN_HASH_DIGITS, checked_prefix, find_programs, list_programs
from ...programs.rendering import MATCH, REFUSED
from .answers import BIGINT_MAX, BadRequest, answered, query_day, query_flag, query_id, query_text, shown, whole
from .pages import wants_json
from .program_views import plot_svg, simulation_report, traced

KINDS = {"draft": True, "released": False}   # the list's --draft / --released


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
        evidence["simulation"] = simulation_report(conn, record.id)
    return evidence


def lookup(request: Request):
    """A program id or the hash on its lineage line (`engine programs show ID | --hash H`): one
    program leads to its page, several are listed, anything else is refused in one line."""
    def work(conn):
        found = find_programs(conn, *_wanted(conn, query_text(request, "q") or ""))
        if len(found) == 1 and not wants_json(request):
            return RedirectResponse(f"/programs/{found[0].id}", status_code=303)
        return shown(request, "lookup.html", {"programs": [record.as_dict() for record in found]},
                     lambda: {"records": found, "asked": request.query_params.get("q", "")})
    return answered(request, work)


def _wanted(conn, text: str) -> tuple[int | None, str | None]:
    """(program id, None) for fewer than MIN_HASH_DIGITS digits, or for the id of a stored program
    (a plant's ids have 11 digits or more: issue 33), (None, hash prefix) otherwise."""
    typed = text.strip()
    if typed.isdigit() and (len(typed) < MIN_HASH_DIGITS or _is_program(conn, typed)):
        return whole("program", typed), None
    try:
        return None, checked_prefix(typed)
    except EngineError:
        raise BadRequest(f"{typed[:40]!r}: give a program id, or {MIN_HASH_DIGITS} or more hex digits of the hash "
                         "on the program's lineage line (`; PROGRAM <id> TEMPLATE <class> v<n> <hash8> INPUT <hash8>`)"
                         ) from None


def _is_program(conn, typed: str) -> bool:
    number = int(typed)
    found = number <= BIGINT_MAX and conn.execute("SELECT 1 FROM program WHERE id = %s", (number,)).fetchone()
    return bool(found)


ROUTES = [Route("/programs", programs, name="programs"), Route("/programs/{program_id}", program, name="program"),
          Route("/lookup", lookup, name="lookup")]
