"""Adversary of issue 32: an address holding a NUL character (%00). No name or id of the engine holds
one and PostgreSQL's text cannot; every page must answer it as bad input, one line with status 400,
never "500 Internal Server Error" (a bug's answer, and a traceback in the service's log)."""
import pytest
from starlette.testclient import TestClient

from engine.service.web.app import create_app

JSON = {"Accept": "application/json"}
# each page that reads a name from the address or the query (the ids are refused as ids already)
ADDRESSES = ["/classes/%00", "/classes/spur%00/impact", "/classes/spur%00/tests", "/machines/hobber%00",
             "/programs?class=%00", "/gears?material=%00", "/lookup?q=%00", "/jobs/1%00"]


@pytest.fixture(scope="module")
def web(read_only_database_url):
    with TestClient(create_app(read_only_database_url), base_url="http://127.0.0.1",
                    raise_server_exceptions=False) as client:
        yield client


@pytest.mark.parametrize("address", ADDRESSES)
def test_a_nul_in_the_address_is_bad_input_in_one_line(web, address):
    answer = web.get(address, headers=JSON)
    assert answer.status_code == 400 and list(answer.json()) == ["error"]
    assert "\n" not in answer.json()["error"]
    assert web.get(address).status_code == 400   # the page too
