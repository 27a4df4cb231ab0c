"""Adversary of issue 32: off loopback (create_app(require_login=True)) no route but the login shows
anything without one: every route of the app, each path parameter filled, as a page, as JSON, as an
SVG, with HEAD, and the spellings a router might take for another (a trailing /, a // in front, a
path through the login). The routes come from the app itself, so a page added later is covered."""
import re

import pytest
from starlette.routing import Route
from starlette.testclient import TestClient

from engine.service.web.app import create_app

FILLED = {"name": "spur", "version": "1", "program_id": "1", "row_id": "1", "gear_id": "42", "job_id": "1"}
SECRET_WORDS = ("postgresql://", "password=")


def every_path(app) -> list[str]:
    paths = []
    for route in app.routes:
        if isinstance(route, Route) and route.path != "/login":
            paths.append(re.sub(r"\{(\w+)(?::\w+)?\}", lambda found: FILLED[found.group(1)], route.path))
    return paths


@pytest.fixture(scope="module")
def web(read_only_database_url):
    with TestClient(create_app(read_only_database_url, require_login=True, session_secret="s"),
                    follow_redirects=False) as client:
        yield client


def test_no_route_answers_without_a_login(web):
    paths = every_path(web.app)
    assert {"/programs/1/plot.svg", "/lookup", "/machines/spur", "/classes/spur/impact"} <= set(paths)
    for path in paths + ["/programs/1/", "//programs/1", "/login/../programs/1", "/login/"]:
        for headers in ({}, {"Accept": "application/json"}, {"Accept": "image/svg+xml"}):
            answer = web.get(path, headers=headers)
            assert answer.status_code in (303, 401), (path, headers)
            assert not any(word in answer.text for word in SECRET_WORDS)
        assert web.head(path).status_code in (303, 401), path
        assert web.post(path).status_code in (303, 401, 405), path   # no form is taken either
