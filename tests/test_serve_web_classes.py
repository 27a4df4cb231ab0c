"""The web view's classes, releases and machines (issue 32), through the app's test client: every
page as HTML and as JSON, the JSON equal to what the CLI's `--json` prints for the same class,
release, draft, golden tests and machine. A release made by hand from SQL is never shown as "gate
passed" (design notes §10); the draft's impact and the golden tests run when asked for; a machine's
page lists what it was sent, newest first, each request linking to its program and job."""
import json
from contextlib import contextmanager

import psycopg
import pytest
from psycopg import sql
from psycopg.types.json import Jsonb
from starlette.testclient import TestClient

from engine.service.web.app import create_app

JSON = {"Accept": "application/json"}
LOOPBACK = "http://127.0.0.1"   # the open web view answers a loopback Host only
COOLANT_ROW = 1800       # seed_templates/classes/spur.csv: cutcond 1, `"M8"` when coolant
COOLANT_OFF_ROW = 2900   # cutcond 2, `"M9"` when coolant: no seeded golden test reads it
EDIT = sql.SQL("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = %s")
GOLDEN_TEST = ("INSERT INTO template_test (gear_class, name, gear_id, expect) "
               "VALUES ('spur', 'coolant_on_before_cutting', 42, ARRAY['line: M8'])")
# A releaser's own call of release_template from SQL, stating results nobody ran (via: 'sql', the
# default, or a forged 'engine').
BY_HAND = """
SELECT release_template(g.name, g.template_version, template_rows_hash(r.rows), %(tests)s, %(impact)s, %(checks)s,
                        via => %(via)s)
FROM gear_class g CROSS JOIN assembled_rows_of(ARRAY[g.name]) r WHERE g.name = 'spur'"""
INVENTED = {"tests": Jsonb([{"class": "spur", "name": "coolant_on_before_cutting", "passed": True}]),
            "impact": Jsonb({"jobs": 7, "changed": 0}),
            "checks": Jsonb({"lint": "passed", "analysis": "no finding", "golden_tests": 1})}


@contextmanager
def web(url, **options):
    with TestClient(create_app(url, **options), base_url=LOOPBACK) as client:
        yield client


def cli_json(run, *args):
    result = run(*args, "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def committed(url, statement, params=()):
    with psycopg.connect(url) as conn:
        cursor = conn.execute(statement, params)
        return cursor.fetchall() if cursor.description else None


def html(client, path):
    page = client.get(path)
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    return page.text


def test_the_classes_page_is_template_list(read_only_run):
    with web(read_only_run.url) as client:
        answer = client.get("/classes", headers=JSON)
        text = html(client, "/classes")
    assert answer.json() == cli_json(read_only_run, "template", "list")
    assert {"spur", "helical", "duplex"} <= {record["class"] for record in answer.json()["classes"]}
    assert '<a href="/classes/spur">spur</a>' in text


def test_a_class_page_is_template_history_and_a_seeded_release_is_not_the_gates(read_only_run):
    """The seed releases the shipped templates: they are said to be released by engine seed, with
    what the re-check finds now, never "gate passed"."""
    with web(read_only_run.url) as client:
        answer = client.get("/classes/spur", headers=JSON).json()
        text = html(client, "/classes/spur")
    assert answer == cli_json(read_only_run, "template", "history", "--class", "spur")
    release = answer["versions"][0]["release"]
    assert release["released_via"] == "seed" and release["gate"] == "not run" and release["recheck"]["passed"]
    assert "gate passed" not in text and "by engine seed, not through the engine&#39;s gate" in text
    history = read_only_run("template", "history", "--class", "spur").stdout
    said = history.splitlines()[1].strip()   # the release's line under v1, as the command prints it
    assert said.startswith("released ") and said.replace("'", "&#39;") in text
    assert "golden test" in text and "gear42" in text   # the class's golden tests are listed
    assert '<a href="/classes/spur/versions/1">v1</a>' in text


def test_a_version_page_is_its_history_entry(read_only_run):
    with web(read_only_run.url) as client:
        first = client.get("/classes/spur/versions/1", headers=JSON).json()
        text = html(client, "/classes/spur/versions/1")
        missing = client.get("/classes/spur/versions/99", headers=JSON)
    history = cli_json(read_only_run, "template", "history", "--class", "spur")
    assert first["version"] == history["versions"][0] and first["diff"] is None
    assert "by engine seed" in text and "gate passed" not in text
    assert missing.status_code == 404 and "no version 99" in missing.json()["error"]


@pytest.mark.slow   # the gate runs twice: seconds
def test_a_release_by_hand_is_never_shown_as_gate_passed_and_the_gates_own_is(run):
    """v2 through `engine template release` shows "gate passed"; v3, a draft the gate refuses
    (a golden test wants M8, the draft writes M9), released by hand from SQL says so and names the
    failing test; v4, the same forged as the engine's gate, is a MISMATCH. The JSON is the CLI's."""
    committed(run.url, EDIT, ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
    assert run("template", "release", "--class", "spur", "--yes").exit_code == 0
    committed(run.url, GOLDEN_TEST)
    for via, row_text in (("sql", '"M9"'), ("engine", '"M9 "')):
        committed(run.url, EDIT, (row_text, COOLANT_ROW))
        assert run("template", "release", "--class", "spur", "--yes").exit_code == 1   # the gate refuses it
        committed(run.url, BY_HAND, {**INVENTED, "via": via})
    with web(run.url) as client:
        answer = client.get("/classes/spur", headers=JSON).json()
        text = html(client, "/classes/spur")
    assert answer == cli_json(run, "template", "history", "--class", "spur")
    releases = {version["version"]: version["release"] for version in answer["versions"] if version["release"]}
    assert [releases[v]["gate"] for v in (2, 3, 4)] == ["passed", "not run", "mismatch"]
    assert {"class": "spur", "name": "coolant_on_before_cutting", "version": 3} in releases[3]["golden_tests"]
    assert "spur/coolant_on_before_cutting" in " ".join(releases[3]["recheck"]["problems"])
    sections = {int(part.split(":", 1)[0]): part for part in text.split('<section class="release">\n<h3>v')[1:]}
    assert "gate passed" in sections[2] and "MISMATCH" not in sections[2]
    assert "gate passed" not in sections[3] and "by hand from SQL" in sections[3]
    assert "spur/coolant_on_before_cutting" in sections[3] and "7 stored job(s)" in sections[3]
    assert "gate passed" not in sections[4] and "MISMATCH" in sections[4]
    with web(run.url) as client:
        third = client.get("/classes/spur/versions/3", headers=JSON).json()
        third_page = html(client, "/classes/spur/versions/3")
    assert third["version"] == next(version for version in answer["versions"] if version["version"] == 3)
    assert third["diff"] == cli_json(run, "template", "diff", "--class", "spur", "--from", 2, "--to", 3)
    assert [change["row_id"] for change in third["diff"]["changes"]] == [COOLANT_ROW]
    assert third["stated_impact"] == {"jobs": 7, "changed": 0}
    assert "by hand from SQL" in third_page and "gate passed" not in third_page


def test_the_drafts_impact_is_computed_on_request_as_the_dry_run(run):
    """Gear 42's stored program; spur's coolant-off line changed in the draft: releasing it would
    change that one program, and the page says so with the diff, as `release --dry-run --json`."""
    assert run("instantiate", "--gear", 42).exit_code == 0
    committed(run.url, EDIT, ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
    with web(run.url) as client:
        assert 'href="/classes/spur/impact"' in html(client, "/classes/spur")
        answer = client.get("/classes/spur/impact", headers=JSON).json()
        text = html(client, "/classes/spur/impact")
    assert answer == cli_json(run, "template", "release", "--class", "spur", "--dry-run")
    assert answer["dry_run"] and not answer["released"]
    assert (answer["impact"]["jobs"], answer["impact"]["changed"], answer["impact"]["proved"]) == (1, 1, 1)
    assert "+M9 ; COOLANT OFF" in answer["impact"]["diffs"][0]["diff"]
    assert "1 program(s) change" in text and "+M9 ; COOLANT OFF" in text
    draft = cli_json(run, "template", "history", "--class", "spur")["versions"][-1]
    assert (draft["state"], draft["release"]) == ("draft", None)   # nothing released


def test_the_class_page_links_the_drafts_impact_only_when_it_has_a_draft(run):
    """The seeded spur has every version released: its page says so instead of linking an impact
    that answers 400 "has no draft"; once a row is edited (a draft), the link is there."""
    with web(run.url) as client:
        before = html(client, "/classes/spur")
        committed(run.url, EDIT, ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
        after = html(client, "/classes/spur")
    draft = cli_json(run, "template", "history", "--class", "spur")["versions"][-1]
    assert 'href="/classes/spur/impact"' not in before and "No draft: every version is released" in before
    assert draft["state"] == "draft"
    assert 'href="/classes/spur/impact"' in after and f"(v{draft['version']}," in after


def test_a_class_without_a_draft_or_failing_its_gate_is_answered_in_one_line(run):
    with web(run.url) as client:
        no_draft = client.get("/classes/helical/impact", headers=JSON)
        committed(run.url, GOLDEN_TEST)
        committed(run.url, EDIT, ('"M9"', COOLANT_ROW))
        refused = client.get("/classes/spur/impact", headers=JSON)
        refused_page = client.get("/classes/spur/impact")
    assert no_draft.status_code == 400 and "has no draft" in no_draft.json()["error"]
    assert refused.status_code == 400 and "not released" in refused.json()["error"]
    assert any("spur/coolant_on_before_cutting" in problem for problem in refused.json()["problems"])
    assert refused_page.status_code == 400 and "spur/coolant_on_before_cutting" in refused_page.text


def test_the_golden_tests_run_on_request_as_engine_test(read_only_run):
    with web(read_only_run.url) as client:
        current = client.get("/classes/spur/tests", headers=JSON).json()
        released = client.get("/classes/spur/tests?released=1", headers=JSON).json()
        text = html(client, "/classes/spur/tests")
    assert current == cli_json(read_only_run, "test", "--class", "spur")
    assert released == cli_json(read_only_run, "test", "--class", "spur", "--released")
    assert current["failed"] == 0 and current["passed"] == len(current["tests"]) > 1
    assert f"{current['passed']} passed, 0 failed" in text and "PASS" in text


def test_an_unknown_class_or_machine_is_a_404_in_one_line(read_only_run):
    with web(read_only_run.url) as client:
        for path in ("/classes/nosuch", "/classes/nosuch/impact", "/classes/nosuch/tests", "/machines/nosuch"):
            answer = client.get(path, headers=JSON)
            assert answer.status_code == 404 and "nosuch" in answer.json()["error"], path
            assert client.get(path).status_code == 404


def test_the_machines_pages_are_machines_list_and_show(read_only_run):
    with web(read_only_run.url) as client:
        listed = client.get("/machines", headers=JSON).json()
        shown = client.get("/machines/hobber-840d", headers=JSON).json()
        text = html(client, "/machines")
        page = html(client, "/machines/hobber-840d")
    assert listed == cli_json(read_only_run, "machines", "list")
    assert shown["machine"] == cli_json(read_only_run, "machines", "show", "hobber-840d")["machine"]
    assert (shown["requests"], shown["request_count"]) == ([], 0)
    assert '<a href="/machines/hobber-840d">hobber-840d</a>' in text and "0 request(s)" in page


REQUEST = ("INSERT INTO program_request (machine, via, client, asked_for, job_id, program_id, refusal, requested_at) "
           "VALUES ('hobber-840d', %s, %s, %s, %s, %s, %s, %s) RETURNING id")


def test_a_machines_page_lists_what_it_was_sent_newest_first(run):
    """Two requests of gear 42's job on hobber-840d: sent (an hour ago, by FTP) and refused (now,
    from the request folder): the refused one first with its reason, the sent one with its
    program, job and the version the program was made from."""
    made = cli_json(run, "instantiate", "--gear", 42)
    program, job = made["program_id"], made["job_id"]
    sent = committed(run.url, REQUEST, ("ftp", "10.0.0.7", "GEAR42.MPF", job, program, None,
                                        "2026-11-29 08:00:00+00"))[0][0]
    reason = "class spur has no released template version"
    refused = committed(run.url, REQUEST, ("folder", "REQ/GEAR42.REQ", "GEAR42", job, None, reason,
                                           "2026-11-29 09:00:00+00"))[0][0]
    with web(run.url) as client:
        answer = client.get("/machines/hobber-840d", headers=JSON).json()
        text = html(client, "/machines/hobber-840d")
    assert answer["request_count"] == 2
    assert [r["request_id"] for r in answer["requests"]] == [refused, sent]
    newest, oldest = answer["requests"]
    assert (newest["program_id"], newest["refusal"], newest["via"]) == (
        None, "class spur has no released template version", "folder")
    assert (oldest["program_id"], oldest["job_id"], oldest["client"], oldest["asked_for"]) == (
        program, job, "10.0.0.7", "GEAR42.MPF")
    assert (oldest["class"], oldest["template_version"], oldest["draft"]) == ("spur", 1, False)
    assert oldest["requested_at"].startswith("2026-11-29T08:00:00")
    assert f'<a href="/programs/{program}">program {program}</a>' in text
    assert f'<a href="/jobs/{job}">job {job}</a>' in text
    assert "refused: class spur has no released template version" in text
    assert text.index("refused: class spur") < text.index(f"program {program}</a>")
