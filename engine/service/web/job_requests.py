"""A runner's request on the web view (issue 32; design notes §10, §11): the button "Make and
send to <machine>" on a job's page has the job's program made for its machine now, by the one
delivery path every control's request takes (engine.service.delivery.deliver, via "web"): from the
class's released version, proved by the machine's verifier and the simulation, stored with its
lineage and recorded in program_request with the login (or "local" on the open loopback view).
The control then gets that very program when it asks for the job (FTP, request folder): the job's
newest program, proved again.

Only a runner asks (engine_runner, or the owner; on loopback the service's own role): a reader is
refused 403 naming the role. The form is a POST that only this service's own pages may send
(auth.cross_site: a page of another site must not make a runner's browser request programs). A
program made answers 303 to its page; a refusal is the job's page again with the one-line reason
(400, JSON {"error": reason}), recorded as every refusal is."""
from __future__ import annotations

from typing import TYPE_CHECKING

from starlette.requests import Request
from starlette.responses import RedirectResponse, Response
from starlette.routing import Route

from ...errors import EngineError
from ...programs.job_records import job_details
from ..delivery import deliver
from ..delivery_names import Refused
from .answers import shown, status_of, whole
from .auth import LOCAL_USER, REQUESTING_ROLE, cross_site, may_request, requester
from .jobs import request_offered
from .pages import connection, refusal, wants_json

if TYPE_CHECKING:
    from ...db.connection import Connection

JOB_MACHINE = "SELECT machine FROM job WHERE id = %s"
NOT_A_RUNNER = (f"job {{job}}: only a member of {REQUESTING_ROLE} may request a program; {{who}} may only see the "
                f"pages: ask the database's owner to GRANT {REQUESTING_ROLE} to it")


def request_program(request: Request) -> Response:
    """POST /jobs/{job_id}/request: the job's program made, proved, stored and recorded for the
    job's machine (see the module's docstring)."""
    reason = cross_site(request)
    if reason is not None:
        return refusal(request, reason, 403)
    if not may_request(request):   # before the page's connection: may_request may take one of its own
        who = "the service's own login" if requester(request) == LOCAL_USER else f"login {requester(request)}"
        return refusal(request, NOT_A_RUNNER.format(job=request.path_params["job_id"][:40], who=who), 403)
    try:
        job_id = whole("job", request.path_params["job_id"])
    except EngineError as error:
        return refusal(request, str(error), status_of(error))
    with connection(request) as conn:
        return _delivered(request, conn, job_id)


def _delivered(request: Request, conn: Connection, job_id: int) -> Response:
    """deliver() on the pool's connection, idle (deliver commits the program and its record itself)."""
    with conn.transaction():
        row = conn.execute(JOB_MACHINE, (job_id,)).fetchone()
    if row is None:
        return refusal(request, f"job {job_id} does not exist; the jobs page lists the stored ones", 404)
    try:
        sent = deliver(conn, row[0], f"JOB {job_id}", via="web", client=requester(request),
                       config=request.app.state.config)
    except Refused as refused:
        return _refused(request, conn, job_id, refused.reason)
    return RedirectResponse(f"/programs/{sent.program_id}", status_code=303)


def _refused(request: Request, conn: Connection, job_id: int, reason: str) -> Response:
    """The job's page again, the reason above its button; JSON {"error": reason}. Status 400."""
    if wants_json(request):
        return refusal(request, reason, 400)
    with conn.transaction():
        details = job_details(conn, job_id)
    return shown(request, "job.html", {"job": details}, lambda: _offered(request, conn, job_id, reason), 400)


def _offered(request: Request, conn: Connection, job_id: int, reason: str) -> dict:
    offered = request_offered(request, conn, job_id, reason)
    return {**offered, "may_request": offered["made_at"] is None}


ROUTES = [Route("/jobs/{job_id}/request", request_program, methods=["POST"], name="request_program")]
