"""What the pages of gears, jobs and programs share: reading a request's ids and filters as the
CLI's options read them (the same ranges, the same one-line refusals), and answering with the
library's result or its one-line refusal. Every page reads on a connection of the app's pool,
in a thread of its own (the library is synchronous; the event loop keeps answering others)."""
from __future__ import annotations

from collections.abc import Callable
from datetime import date, datetime
from typing import Any

from starlette.requests import Request
from starlette.responses import Response

from ...db.origin import LAST_PLANT
from ...errors import EngineError
from ...json_text import cell
from .pages import TEMPLATES, connection, page, refusal, wants_json

# the id ranges of the columns each names (schema/schema.sql; the CLI's engine/cli/ids.py)
INTEGER_MAX = 2**31 - 1
BIGINT_MAX = 2**63 - 1
ID_RANGES = {"gear": (1, INTEGER_MAX), "job": (1, BIGINT_MAX), "program": (1, BIGINT_MAX),
             "row": (0, INTEGER_MAX), "line": (1, INTEGER_MAX), "plant": (0, LAST_PLANT)}
# how the library says a record is not there (engine.db.listing.one_record, engine.programs.lookup):
# such a refusal answers 404, any other 400
NOT_FOUND_WORDS = (" does not exist", "no program has ", " is not in the program's template version")


class BadRequest(EngineError):
    """A request's value the page cannot take (a word for an id, a day that is none): 400."""


def digits(text: str) -> bool:
    """ASCII digits only, as a control and the records show an id: str.isdigit() is also true of
    `²`, which int() refuses, and of `８１２`, which it reads as 812."""
    return text.isascii() and text.isdigit()


def whole(kind: str, text: str) -> int:
    """The id `text` of a `kind` (gear, job, program, row); BadRequest naming the range otherwise."""
    low, high = ID_RANGES[kind]
    value = text.strip()   # no more digits than the highest id: int() refuses over 4300 (a stack trace)
    if not digits(value) or len(value) > len(str(high)) or not low <= int(value) <= high:
        raise BadRequest(f"{kind} {value[:40]!r}: give a {kind} id, a whole number from {low} to {high}")
    return int(value)


def query_id(request: Request, name: str, kind: str) -> int | None:
    """The id of the query parameter `name`, or None if it is absent or empty (a form left blank)."""
    value = request.query_params.get(name, "").strip()
    return whole(kind, value) if value else None


def query_text(request: Request, name: str) -> str | None:
    return request.query_params.get(name, "").strip() or None


def query_day(request: Request, name: str) -> date | None:
    """A --since/--until day: YYYY-MM-DD, or None."""
    value = query_text(request, name)
    if value is None:
        return None
    try:
        return datetime.strptime(value, "%Y-%m-%d").date()
    except ValueError:
        raise BadRequest(f"{name} {value[:40]!r}: give a day as YYYY-MM-DD") from None


def query_flag(request: Request, name: str) -> bool:
    return query_text(request, name) not in (None, "0", "false", "no", "off")


def answered(request: Request, work: Callable[[Any], Response]) -> Response:
    """`work(conn)`'s page, or the engine's one-line refusal: 404 for a record not there, else 400."""
    try:
        with connection(request) as conn:
            return work(conn)
    except EngineError as error:
        return refusal(request, str(error), status_of(error))


def status_of(error: EngineError) -> int:
    message = str(error)
    if not isinstance(error, BadRequest) and any(words in message for words in NOT_FOUND_WORDS):
        return 404
    return 400


TEMPLATES.env.filters["cell"] = cell


def shown(request: Request, template: str, data: dict, more: Callable[[], dict], status: int = 200) -> Response:
    """A page that shows more than its JSON holds (a program's plot, its trace): the JSON is `data`
    alone, the command's; `more()` is computed only for the HTML page."""
    if wants_json(request):
        return page(request, template, data, status)
    return TEMPLATES.TemplateResponse(request, template, {"data": data, **more()}, status_code=status)
