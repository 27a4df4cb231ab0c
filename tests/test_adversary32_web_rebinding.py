"""Adversary of issue 32: the open web view (bound to 127.0.0.1, no login) is the local user's, yet a
page of another site can read it through the local user's browser by DNS rebinding: its name
(evil.example) made to resolve to 127.0.0.1, so the browser sends GET /programs with
`Host: evil.example:8080` and lets that site's script read the answer (same origin for the browser).
Every page of the open view must answer only a loopback Host (127.0.0.1, localhost, [::1]); the
runner's POST already checked it (auth.cross_site), the pages did not."""
import pytest
from starlette.testclient import TestClient

from engine.service.web.app import create_app

PAGES = ["/", "/programs", "/gears/42", "/machines/hobber-840d", "/classes/spur", "/lookup?q=1"]


@pytest.fixture(scope="module")
def app(read_only_database_url):
    return create_app(read_only_database_url)


@pytest.mark.parametrize("host", ["evil.example:8080", "192.168.1.20:8080", "127.0.0.1.evil.example", ""])
def test_the_open_view_answers_no_other_host(app, host):
    with TestClient(app, base_url="http://127.0.0.1:8080", follow_redirects=False) as client:
        for path in PAGES:
            answer = client.get(path, headers={"Host": host, "Accept": "application/json"})
            assert answer.status_code == 421 and list(answer.json()) == ["error"], (host, path)
            assert "127.0.0.1" in answer.json()["error"] and "\n" not in answer.json()["error"]
            assert "spur" not in client.get(path, headers={"Host": host}).text


@pytest.mark.parametrize("host", ["127.0.0.1:8080", "localhost:8080", "[::1]:8080", "127.0.0.1", "LOCALHOST"])
def test_the_open_view_answers_its_loopback_names(app, host):
    with TestClient(app, base_url="http://127.0.0.1:8080") as client:
        assert client.get("/classes/spur", headers={"Host": host}).status_code == 200
