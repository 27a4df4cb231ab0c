"""Machines on the web view (issue 32): every machine record, and a machine's page with its record
and what it was sent: the requests of program_request, newest first, each linking to its program
and job, a refusal with its one-line reason, and the class and template version each program was
made from. The machine's record and the list are `engine machines show | list --json`'s."""
from __future__ import annotations

from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from ...errors import EngineError
from .pages import connection, page, refusal


def machines_list(request: Request) -> Response:
    """Every machine record: `engine machines list --json`."""
    from msgspec.structs import asdict

    from ...machines.records import all_machines

    with connection(request) as conn:
        machines = all_machines(conn)
    return page(request, "machines.html", {"machines": [asdict(machine) for machine in machines]})


def machine_page(request: Request) -> Response:
    """A machine: `engine machines show NAME --json`'s record, and `requests`, what it was sent
    (newest first; `request_count` in all)."""
    from ...machines.importing import show_machine
    from ..requests import machine_requests

    name = request.path_params["name"]
    with connection(request) as conn:
        try:
            record = show_machine(conn, name)
        except EngineError as error:
            return refusal(request, str(error), 404)
        requests, count = machine_requests(conn, name)
    return page(request, "machine.html", {"machine": record, "requests": requests, "request_count": count})


ROUTES = [
    Route("/machines", machines_list, name="machines"),
    Route("/machines/{name}", machine_page, name="machine"),
]
