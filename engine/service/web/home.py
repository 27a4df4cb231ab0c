"""The start page: what the service shows, and the look-up an operator needs at the control."""
from __future__ import annotations

from starlette.requests import Request
from starlette.routing import Route

from .pages import page


async def home(request: Request):
    return page(request, "home.html", {"pages": ["gears", "jobs", "programs", "classes", "machines"]})


ROUTES = [Route("/", home, name="home")]
