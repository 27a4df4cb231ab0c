"""The gears: a list with the filters of `engine gears list` and a gear's page with its units and
jobs (`engine gears show`), the JSON of each the command's --json."""
from __future__ import annotations

from starlette.requests import Request
from starlette.routing import Route

from ...gears.gear_records import gear_details, list_gears
from .answers import answered, query_day, query_text, whole
from .pages import page


def gears(request: Request):
    """`engine gears list [--class C] [--since D] [--until D] --json`."""
    def work(conn):
        found = list_gears(conn, query_text(request, "class"), query_day(request, "since"), query_day(request, "until"))
        return page(request, "gears.html", {"gears": found})
    return answered(request, work)


def gear(request: Request):
    """`engine gears show ID --json`."""
    return answered(request, lambda conn: page(request, "gear.html", {
        "gear": gear_details(conn, whole("gear", request.path_params["gear_id"]))}))


ROUTES = [Route("/gears", gears, name="gears"), Route("/gears/{gear_id}", gear, name="gear")]
