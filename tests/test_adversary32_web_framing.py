"""Adversary of issue 32: a page of another site framed the open view's job page
(<iframe src="http://127.0.0.1:8080/jobs/7">) under a decoy, so the local user's click landed on
"Make and send to hobber-840d": the form's POST comes from the framed page itself, so its Origin is
this service's and the cross-site check takes it (clickjacking). No page of the view may be shown
in another site's frame: every answer tells the browser so (X-Frame-Options, and CSP
frame-ancestors, which browsers obey over it)."""
import pytest
from starlette.testclient import TestClient

from engine.service.web.app import create_app


@pytest.fixture(scope="module")
def web(read_only_database_url):
    with TestClient(create_app(read_only_database_url), base_url="http://127.0.0.1:8080",
                    follow_redirects=False) as client:
        yield client


@pytest.mark.parametrize("path", ["/jobs/1", "/", "/programs", "/login", "/programs/1/plot.svg", "/nothing-here"])
def test_no_page_may_be_framed_by_another_site(web, path):
    answer = web.get(path)
    assert answer.headers["x-frame-options"] == "DENY", path
    assert "frame-ancestors 'none'" in answer.headers["content-security-policy"], path
