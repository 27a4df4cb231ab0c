"""The jobs: a list with the filters of `engine jobs list` and a job's page with its parameters
and programs (`engine jobs show`), the JSON of each the command's --json."""
from __future__ import annotations

from starlette.requests import Request
from starlette.routing import Route

from ...db.origin import made_elsewhere, plant_name, this_plant
from ...programs.job_records import job_details, list_jobs
from .answers import answered, query_day, query_id, query_text, shown, whole
from .auth import may_request


def jobs(request: Request):
    """`engine jobs list [--class C] [--gear ID] [--plant N] [--since D] [--until D] --json`."""
    def work(conn):
        found = list_jobs(conn, query_text(request, "class"), query_id(request, "gear", "gear"),
                          query_day(request, "since"), query_day(request, "until"),
                          query_id(request, "plant", "plant"))
        return shown(request, "jobs.html", {"jobs": found}, lambda: {"here": this_plant(conn)})
    return answered(request, work)


def job(request: Request):
    """`engine jobs show ID --json`; the page adds, for a runner, the button that requests the
    job's program for its machine (engine.service.web.job_requests); never for a job another plant
    made (engine.db.origin): it is made and sent there, on its own gear."""
    def work(conn):
        job_id = whole("job", request.path_params["job_id"])
        return shown(request, "job.html", {"job": job_details(conn, job_id)},
                     lambda: request_offered(request, conn, job_id, None))
    return answered(request, work)


def request_offered(request: Request, conn, job_id: int, refused: str | None) -> dict:
    """Whether the page offers "Make and send", and the plant that made the job if not this one."""
    elsewhere = made_elsewhere(conn, job_id)
    return {"may_request": elsewhere is None and may_request(request, conn), "refused": refused,
            "made_at": None if elsewhere is None else plant_name(elsewhere)}


ROUTES = [Route("/jobs", jobs, name="jobs"), Route("/jobs/{job_id}", job, name="job")]
