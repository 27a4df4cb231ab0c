"""The jobs: a list with the filters of `engine jobs list` and a job's page with its parameters
and programs (`engine jobs show`), the JSON of each the command's --json."""
from __future__ import annotations

from starlette.requests import Request
from starlette.routing import Route

from ...programs.job_records import job_details, list_jobs
from .answers import answered, query_day, query_id, query_text, shown, whole
from .auth import may_request
from .pages import page


def jobs(request: Request):
    """`engine jobs list [--class C] [--gear ID] [--since D] [--until D] --json`."""
    def work(conn):
        found = list_jobs(conn, query_text(request, "class"), query_id(request, "gear", "gear"),
                          query_day(request, "since"), query_day(request, "until"))
        return page(request, "jobs.html", {"jobs": found})
    return answered(request, work)


def job(request: Request):
    """`engine jobs show ID --json`; the page adds, for a runner, the button that requests the
    job's program for its machine (engine.service.web.job_requests)."""
    return answered(request, lambda conn: shown(request, "job.html", {
        "job": job_details(conn, whole("job", request.path_params["job_id"]))},
        lambda: {"may_request": may_request(request, conn), "refused": None}))


ROUTES = [Route("/jobs", jobs, name="jobs"), Route("/jobs/{job_id}", job, name="job")]
