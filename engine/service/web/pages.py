"""How every page answers: HTML from a Jinja2 template, or the same data as JSON when the
request asks for it (`Accept: application/json`), with the keys the CLI's `--json` prints.
A handled error (engine.errors.EngineError: an unknown id, a refusal) is its one line, as the CLI
prints it, with status 404 or 400; nothing else of the engine's state is shown."""
from __future__ import annotations

import re
from contextlib import contextmanager
from pathlib import Path
from urllib.parse import unquote_to_bytes

from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.templating import Jinja2Templates
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ...json_text import exact_json

TEMPLATES = Jinja2Templates(directory=str(Path(__file__).parent / "templates"))
# every answer: no page of this view in another site's frame (X-Frame-Options for older browsers)
NOT_FRAMED = [(b"x-frame-options", b"DENY"), (b"content-security-policy", b"frame-ancestors 'none'")]
# The CLI's advice (the clause after a refusal's last "; ", naming a command) as a page says it: a
# browser's user has the look-up box and the pages, not the CLI (the review of issue 32 found
# /programs/99999 advising `engine programs show --hash H`). (command as the CLI names it, page advice)
PAGE_ADVICE = (
    ("engine programs show --hash", "find it by its lineage line: type the hash on it in the look-up box at the top"),
    ("engine programs list", "the Programs page lists the programs"),
    ("SELECT id, name FROM program", "the Programs page lists the programs"),
    ("engine jobs list", "the Jobs page lists the jobs"),
    ("engine gears", "the Gears page lists the gears"),
    ("engine template list", "the Classes page lists the classes"),
    ("engine template history", "the class's page lists its versions"),
    ("engine machines list", "the Machines page lists the machines"),
    ("engine explain --program", "the program's page shows the rows it was made from"),
)
COMMAND = re.compile(r"`(?P<command>[^`]+)`")
NUL_REFUSED = "the address holds a NUL character (%00), which no name, id or hash of the engine has; remove it"


def wants_json(request: Request) -> bool:
    """JSON when the client prefers it to HTML (a browser sends text/html first)."""
    accept = request.headers.get("accept", "")
    return "application/json" in accept and "text/html" not in accept


def page(request: Request, template: str, data: dict, status: int = 200) -> Response:
    """The page `template` showing `data`, or `data` itself as JSON, written as the CLI's --json
    writes it (engine.json_text: a time as str() gives it, a numeric value with its digits), so a
    page's JSON is the command's."""
    if wants_json(request):
        return Response(exact_json(data), status_code=status, media_type="application/json")
    return TEMPLATES.TemplateResponse(request, template, {"data": data}, status_code=status)


def refusal(request: Request, message: str, status: int = 400) -> Response:
    """A one-line error, as JSON {"error": …} (the CLI's line) or a page saying it (for_pages)."""
    if wants_json(request):
        return JSONResponse({"error": message}, status_code=status)
    return TEMPLATES.TemplateResponse(request, "error.html", {"message": for_pages(message)}, status_code=status)


def for_pages(message: str) -> str:
    """The refusal with its command advice said as page advice (PAGE_ADVICE); the JSON keeps the
    CLI's line (a program reading it runs the commands). Advice naming no command of the table is
    kept as it is."""
    reason, _, advice = message.rpartition("; ")
    named = COMMAND.search(advice)
    if not reason or named is None:
        return message
    page_advice = next((said for command, said in PAGE_ADVICE if named.group("command").startswith(command)), None)
    return message if page_advice is None else f"{reason}; {page_advice}"


@contextmanager
def connection(request: Request):
    """A connection of the app's pool for one page; rolled back after (pages only read; a
    page that stores, as a runner's program request, commits in its own transaction)."""
    with request.app.state.pool.connection() as conn:
        yield conn


def html(text: str, status: int = 200) -> HTMLResponse:
    return HTMLResponse(text, status_code=status)


class NulRefused:
    """An address holding a NUL (%00 in its path or query) answered as bad input: 400 and one line.
    No name, id or hash of the engine holds one and PostgreSQL's text cannot, so a page reading it
    would fail in the database with an error of the server (500, a traceback in the log): the
    adversary of issue 32 found /classes/%00, /machines/x%00 and /programs?class=%00 doing so."""

    def __init__(self, app: ASGIApp):
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and ("\0" in scope["path"] or b"\0" in unquote_to_bytes(scope["query_string"])):
            return await refusal(Request(scope, receive), NUL_REFUSED)(scope, receive, send)
        await self.app(scope, receive, send)


class NotFramed:
    """Every answer forbids the browser to show it in a frame of another site. A site framing the
    open view's job page under a decoy had the local user's click land on "Make and send" (the
    adversary of issue 32): the form's POST then comes from the framed page, with this service's
    own Origin, which the cross-site check takes (clickjacking)."""

    def __init__(self, app: ASGIApp):
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)

        async def framed_nowhere(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), *NOT_FRAMED]}
            await send(message)
        await self.app(scope, receive, framed_nowhere)
