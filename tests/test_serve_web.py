"""The web view of `engine serve` (issue 32), asked as a browser and as a program would ask it:
every page of gears, jobs and programs answers, its JSON is the matching command's --json for the
same record (the CLI run on the same database is the reference), a program's status is the
check's (a forged program is MISMATCH, and nothing is drawn or traced of it), text that users
wrote is escaped, and a bad or unknown id is one line, never a stack trace. `engine serve` itself
is started as a real process, fetched over HTTP and stopped with `engine serve stop`."""
from __future__ import annotations

import html
import json
import re
import signal
import socket
import subprocess
import urllib.request
from pathlib import Path

import psycopg
import pytest
from helpers.class_jobs import PAWN
from helpers.roles import as_role
from helpers.serve_process import engine, free_port
from starlette.testclient import TestClient

from engine.service.web.app import create_app

GEAR = 42                        # the seeded spur gear: the paper's n0 = 246 r/min
SPINDLE_LINE = "M3 S246"
SPINDLE_ROW = 1700               # the spur class's row that emits it (seed_templates/classes/spur.csv)
JSON = {"Accept": "application/json"}
LOOPBACK = "http://127.0.0.1"   # the open web view answers a loopback Host only
HOSTILE = "<script>alert(1)</script>"


@pytest.fixture
def made(run):
    """(run, client, job id, program id) of gear 42's program made by the CLI, and the web view on
    the same database."""
    result = run("instantiate", "--gear", GEAR, "--json")
    assert result.exit_code == 0, result.output
    program = json.loads(result.stdout)
    with TestClient(create_app(run.url), base_url=LOOPBACK) as client:
        yield run, client, program["job_id"], program["program_id"]


def cli_json(run, *args) -> dict:
    result = run(*args)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def web_json(client, path: str, status: int = 200) -> dict:
    answer = client.get(path, headers=JSON)
    assert answer.status_code == status, answer.text
    assert answer.headers["content-type"].startswith("application/json")
    return answer.json()


def input_hash(run, program_id: int) -> str:
    return cli_json(run, "programs", "show", program_id, "--json")["programs"][0]["input_hash"]


def test_every_page_answers_as_json_what_the_command_prints(made):
    run, client, job_id, program_id = made
    digest = input_hash(run, program_id)[:8]
    pairs = {   # page -> the command whose --json it answers
        "/gears": ("gears", "list", "--json"),
        "/gears?class=spur&since=2020-01-01": ("gears", "list", "--class", "spur", "--since", "2020-01-01", "--json"),
        f"/gears/{GEAR}": ("gears", "show", GEAR, "--json"),
        "/jobs": ("jobs", "list", "--json"),
        f"/jobs?gear={GEAR}": ("jobs", "list", "--gear", GEAR, "--json"),
        f"/jobs/{job_id}": ("jobs", "show", job_id, "--json"),
        "/programs": ("programs", "list", "--json"),
        f"/programs?gear={GEAR}&kind=released&check=1": ("programs", "list", "--gear", GEAR, "--released", "--check",
                                                         "--json"),
        f"/programs?job={job_id}&kind=draft": ("programs", "list", "--job", job_id, "--draft", "--json"),
        f"/programs/{program_id}": ("programs", "show", program_id, "--json"),
        f"/lookup?q={digest}": ("programs", "show", "--hash", digest, "--json"),
        f"/programs/{program_id}/trace": ("explain", "--program", program_id, "--json"),
        f"/programs/{program_id}/rows/{SPINDLE_ROW}": ("explain", "--program", program_id, "--row", SPINDLE_ROW,
                                                       "--json"),
        f"/programs/{program_id}/simulation": ("simulate", "--program", program_id, "--json"),
    }
    for path, command in pairs.items():
        assert web_json(client, path) == cli_json(run, *command), path


def test_the_program_page_shows_the_checked_program_its_trace_plot_and_simulation(made):
    run, client, job_id, program_id = made
    page = client.get(f"/programs/{program_id}")
    assert page.status_code == 200
    text = page.text
    assert re.search(r'id="status">MATCH<', text) and "DRAFT" not in text and "UNVERIFIED" not in text
    assert "read by the machine&#39;s verifier" in text
    # the lineage line (design notes §7: `; PROGRAM <id> TEMPLATE <class> v<n> <hash8> INPUT <hash8>`)
    assert f"; PROGRAM {program_id} TEMPLATE spur v1 " in text
    assert f"INPUT {input_hash(run, program_id)[:8]}" in text
    # every line of a template row leads to that row's trace
    spindle = re.search(rf'<a href="/programs/{program_id}/rows/(\d+)" title="[^"]*">{SPINDLE_LINE}</a>', text)
    assert spindle and int(spindle.group(1)) == SPINDLE_ROW
    lines = cli_json(run, "programs", "show", program_id, "--json")["programs"][0]["lines"]
    assert text.count(f'<a href="/programs/{program_id}/rows/') == len(lines) - 1   # all but the lineage line
    svg = re.search(r'<figure class="plot" id="plot">(<svg.*?</svg>)', text, re.S)
    assert svg and "<path" in svg.group(1)
    simulated = run("simulate", "--program", program_id)
    assert simulated.exit_code == 0
    assert all(line.replace("'", "&#39;").replace('"', "&#34;") in text for line in simulated.stdout.splitlines())
    row = client.get(f"/programs/{program_id}/rows/{SPINDLE_ROW}")
    assert row.status_code == 200 and f"{SPINDLE_ROW} {SPINDLE_LINE} emitted: n0 = 246 (job)" in row.text
    assert client.get(f"/programs/{program_id}/trace").text.count('<section class="row"') == len(
        cli_json(run, "explain", "--program", program_id, "--json")["rows"])
    drawn = client.get(f"/programs/{program_id}/plot.svg")
    assert drawn.status_code == 200 and drawn.headers["content-type"].startswith("image/svg+xml")


def test_the_pages_of_gears_and_jobs_lead_to_each_other(made):
    run, client, job_id, program_id = made
    for path, links in {"/gears": [f'href="/gears/{GEAR}"'], f"/gears/{GEAR}": [f'href="/jobs/{job_id}"'],
                        "/jobs": [f'href="/jobs/{job_id}"', f'href="/gears/{GEAR}"'],
                        f"/jobs/{job_id}": [f'href="/programs/{program_id}"', f'href="/gears/{GEAR}"'],
                        "/programs": [f'href="/programs/{program_id}"'], "/": ['href="/programs"']}.items():
        page = client.get(path)
        assert page.status_code == 200 and page.headers["content-type"].startswith("text/html"), path
        assert all(link in page.text for link in links), path


def test_the_lookup_leads_from_the_hash_on_the_control_to_the_program(made):
    run, client, job_id, program_id = made
    digest = input_hash(run, program_id)
    for typed in (digest[:8], digest[:8].upper(), f" {digest} ", str(program_id)):
        found = client.get("/lookup", params={"q": typed}, follow_redirects=False)
        assert found.status_code == 303 and found.headers["location"] == f"/programs/{program_id}", typed
    again = cli_json(run, "instantiate", "--gear", GEAR, "--json")["program_id"]   # same version: same template hash
    template = cli_json(run, "programs", "show", program_id, "--json")["programs"][0]["template_hash"]
    listed = client.get("/lookup", params={"q": template[:8]})
    assert listed.status_code == 200
    assert f'href="/programs/{program_id}"' in listed.text and f'href="/programs/{again}"' in listed.text


def lineage_of(run, program_id: int) -> str:
    """The program's lineage line as the control shows it (the CLI's record of the program)."""
    lines = cli_json(run, "programs", "show", program_id, "--json")["programs"][0]["lines"]
    return next(line for line in lines if line.startswith(f"; PROGRAM {program_id} TEMPLATE "))


def test_a_whole_lineage_line_pasted_in_the_lookup_leads_to_its_program(made):
    """The review of issue 32: the whole line read off the control was refused, shown cut at 40
    characters. It leads to its program, in the 840D's form and the Fanuc's (parentheses)."""
    run, client, job_id, program_id = made
    line = lineage_of(run, program_id)
    words = line.removeprefix("; ")
    for typed in (line, f"({words})", f"( {words} )", f"N20 {line}", f"  {line.lower()}  "):
        found = client.get("/lookup", params={"q": typed}, follow_redirects=False)
        assert found.status_code == 303 and found.headers["location"] == f"/programs/{program_id}", typed
    as_json = client.get("/lookup", params={"q": line}, headers=JSON).json()
    assert [record["program_id"] for record in as_json["programs"]] == [program_id]


def test_a_lineage_line_whose_hashes_are_another_programs_is_refused_saying_so(made):
    run, client, job_id, program_id = made
    other = cli_json(run, "instantiate", "--gear", 43, "--json")["program_id"]   # another gear: another INPUT hash
    other_line = lineage_of(run, other)
    borrowed = other_line.replace(f"PROGRAM {other} ", f"PROGRAM {program_id} ")   # this id, the other's hashes
    refused = client.get("/lookup", params={"q": borrowed}, headers=JSON)
    page = client.get("/lookup", params={"q": borrowed})
    assert refused.status_code == page.status_code == 400
    message = refused.json()["error"]
    assert message.startswith(f"the lineage line names program {program_id}, but its TEMPLATE ")
    assert f"is not program {program_id}'s" in message and f"its hashes are those of program {other}:" in message
    assert message in html.unescape(page.text)
    cut = client.get("/lookup", params={"q": borrowed.rsplit(" INPUT", 1)[0]}, headers=JSON).json()["error"]
    assert "reads as a lineage line but not a whole one" in cut and repr(borrowed.rsplit(" INPUT", 1)[0]) in cut


def test_a_refused_query_is_shown_whole_and_escaped(made):
    run, client, job_id, program_id = made
    typed = f"{HOSTILE} is what the control shows at line 40 of the program"   # more than 40 characters
    refused = client.get("/lookup", params={"q": typed})
    assert refused.status_code == 400 and repr(typed) in html.unescape(refused.text)
    assert HOSTILE not in refused.text


def forged(url: str, program_id: int) -> int:
    """A copy of the program stored the way a runner can (engine_runner, program_submission), its
    spindle line changed to one no template makes, with markup in its comment; → its id."""
    with psycopg.connect(url) as conn, as_role(conn, "engine_runner"):
        lines, row_ids, trace, job_id, gear_class, version, digest, name = conn.execute(
            "SELECT lines, row_ids, trace, job_id, gear_class, template_version, template_hash, name "
            "FROM program WHERE id = %s", (program_id,)).fetchone()
        new_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
        lines = [f"M3 S900 ; {HOSTILE}" if line == SPINDLE_LINE else
                 line.replace(f"PROGRAM {program_id} ", f"PROGRAM {new_id} ") for line in lines]
        conn.execute("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, "
                     "name, lines, row_ids, trace) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s)",
                     (new_id, job_id, gear_class, version, digest, name, lines, row_ids, json.dumps(trace)))
    return new_id


def test_a_forged_program_is_shown_as_the_mismatch_it_is_and_nothing_of_it_is_evidence(made):
    run, client, job_id, genuine = made
    forgery = forged(run.url, genuine)
    shown = cli_json(run, "programs", "show", forgery, "--json")
    assert shown["programs"][0]["rendering"]["status"] == "MISMATCH"
    assert web_json(client, f"/programs/{forgery}") == shown
    page = client.get(f"/programs/{forgery}")
    assert page.status_code == 200 and 'id="status">MISMATCH<' in page.text
    assert "read by the machine" not in page.text and "<svg" not in page.text
    assert f'href="/programs/{forgery}/rows/' not in page.text   # its lines lead to no trace
    assert HOSTILE not in page.text and "M3 S900 ; &lt;script&gt;alert(1)&lt;/script&gt;" in page.text
    for path in ("plot.svg", "trace", f"rows/{SPINDLE_ROW}", "simulation"):
        refused = client.get(f"/programs/{forgery}/{path}", headers=JSON)
        assert refused.status_code == 400 and "MISMATCH" in refused.json()["error"], path
        assert len(refused.json()["error"].splitlines()) == 1


# A lathe whose dialect the verifier has no grammar for: a program for it is stored unverified.
FAGOR_LATHE = ("INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
               "VALUES ('lathe-fagor', 'lathe', 'fagor', 0, 400, -600, 200, 4000)")


def test_a_draft_unverified_program_says_so_and_never_that_a_verifier_read_it(made):
    run, client, job_id, program_id = made
    with psycopg.connect(run.url) as conn:
        conn.execute(FAGOR_LATHE)
    assert run("import-nc", PAWN, "--class", "pawn").exit_code == 0
    stored = cli_json(run, "instantiate", "--class", "pawn", "--machine", "lathe-fagor", "--draft", "--unverified",
                      "--json")["program_id"]
    shown = cli_json(run, "programs", "show", stored, "--json")
    assert shown["programs"][0]["draft"] and shown["programs"][0]["unverified"]
    assert web_json(client, f"/programs/{stored}") == shown
    page = client.get(f"/programs/{stored}").text
    status = shown["programs"][0]["rendering"]["status"]
    assert f'id="status">{status}<' in page
    assert '<span class="status status-draft">DRAFT</span>' in page
    assert '<span class="status status-unverified">UNVERIFIED</span>' in page
    assert "UNVERIFIED: no verifier read it, never written to a file" in page and "read by the machine" not in page


def test_text_users_wrote_is_escaped_on_every_page(made, tmp_path):
    run, client, job_id, program_id = made
    gears = tmp_path / "gears.csv"
    gears.write_text(f"gear_id,module,teeth,face_width,material\n90001,2,20,15,\"{HOSTILE}\"\n")
    assert run("gears", "import", gears).exit_code == 0
    for path in ("/gears", "/gears/90001", f"/lookup?q={HOSTILE}", f"/gears?class={HOSTILE}"):
        page = client.get(path)
        assert HOSTILE not in page.text and "&lt;script&gt;" in page.text, path


BAD = {   # path -> status: a value that is no id is 400, an id (or class) of nothing 404; one line either way
    "/programs/abc": 400, "/programs/0": 400, "/programs/-1": 400, "/programs/99999999999999999999": 400,
    "/programs/99999": 404, "/gears/x1": 400, "/gears/99999999999": 400, "/gears/99999": 404,
    "/jobs/1.5": 400, "/jobs/99999": 404, "/programs/99999/trace": 404, "/programs/99999/simulation": 404,
    "/programs/abc/rows/1": 400, "/lookup?q=zz": 400, "/lookup": 400, "/lookup?q=ffffffff0": 404,
    "/programs?gear=abc": 400, "/programs?kind=final": 400, "/jobs?since=2026-02-30": 400,
    "/gears?class=nosuch": 404, "/nosuch": 404,
}


@pytest.mark.parametrize("path", sorted(BAD))
def test_a_bad_or_unknown_id_is_one_line_never_a_stack_trace(read_only_database_url, path):
    with TestClient(create_app(read_only_database_url), base_url=LOOPBACK) as client:
        page = client.get(path)
        answer = client.get(path, headers=JSON)
    assert page.status_code == answer.status_code == BAD[path]
    assert "Traceback" not in page.text and "File \"" not in page.text
    assert answer.headers["content-type"] == "application/json" and page.headers["content-type"].startswith("text/html")
    message = answer.json()["error"]
    assert len(message.splitlines()) == 1 and message.strip()
    assert message.partition("; ")[0] in html.unescape(page.text)
    assert "`engine " not in html.unescape(page.text)   # a page advises pages, never a command


def test_an_unknown_program_s_page_advises_the_look_up_box_and_its_json_is_the_cli_line(read_only_run):
    """The review of issue 32: /programs/99999 said `engine programs show --hash H` to a browser's
    user. The page names the look-up box; the JSON keeps what `engine programs show 99999` says."""
    cli = read_only_run("programs", "show", 99999)
    assert cli.exit_code == 1
    with TestClient(create_app(read_only_run.url), base_url=LOOPBACK) as client:
        page = client.get("/programs/99999")
        answer = client.get("/programs/99999", headers=JSON)
    assert page.status_code == answer.status_code == 404
    assert answer.json()["error"] in cli.output and "engine programs show --hash H" in answer.json()["error"]
    said = html.unescape(page.text)
    assert "program 99999 does not exist; find it by its lineage line: type the hash on it in the look-up box" in said
    assert "engine programs" not in said and 'name="q"' in page.text   # the box is on the page


def test_an_address_of_no_page_answers_json_to_a_program_and_a_page_to_a_browser(read_only_database_url):
    """Starlette's own 404 and 405 were text/plain "Not Found": a program asking for JSON could not
    read it (the review of issue 32). The error names the address and where the pages are."""
    with TestClient(create_app(read_only_database_url), base_url=LOOPBACK) as client:
        unknown = client.get("/programz/812", headers=JSON)
        browser = client.get("/programz/812", headers={"Accept": "text/html"})
        method = client.delete("/programs", headers=JSON)
    assert unknown.status_code == browser.status_code == 404 and method.status_code == 405
    assert unknown.json() == {"error": "no page at '/programz/812': the home page / leads to every page (gears, "
                                       "jobs, programs, classes, machines)"}
    assert browser.headers["content-type"].startswith("text/html") and "no page at" in html.unescape(browser.text)
    assert method.json() == {"error": "DELETE is not taken at '/programs'; it takes GET, HEAD"}
    assert set(method.headers["allow"].split(", ")) == {"GET", "HEAD"}
    assert method.headers["content-type"] == "application/json"


def started(url: str, runtime: Path) -> tuple[subprocess.Popen, str]:
    """`engine serve` on a free port, and the address it says to open (read from its first line)."""
    service = engine("--database-url", url, "serve", "--port", str(free_port()), runtime=runtime)
    first = service.stdout.readline()
    found = re.search(r"http://127\.0\.0\.1:\d+/", first)
    assert found, first + service.stderr.read()
    return service, found.group(0)


def test_engine_serve_answers_over_http_until_serve_stop(read_only_database_url, tmp_path):
    service, address = started(read_only_database_url, tmp_path)
    try:
        with urllib.request.urlopen(urllib.request.Request(f"{address}gears/{GEAR}", headers=JSON)) as answer:
            assert json.load(answer)["gear"]["teeth"] == 19
        second = engine("--database-url", read_only_database_url, "serve", "--port", str(free_port()),
                        runtime=tmp_path)
        out, err = second.communicate()
        assert second.returncode == 1 and "already runs" in err and len(err.splitlines()) == 1
        stop = engine("serve", "stop", runtime=tmp_path)
        out, err = stop.communicate()
        assert stop.returncode == 0 and f"at {address}" in out, err
        out, err = service.communicate()
        assert service.returncode == 0 and "stopped" in out, err
    finally:
        if service.poll() is None:
            service.kill()
    stop = engine("serve", "stop", runtime=tmp_path)
    out, err = stop.communicate()
    assert stop.returncode == 1 and err.startswith("error: no engine serve is running") and len(err.splitlines()) == 1


def test_ctrl_c_ends_engine_serve_with_exit_130_and_one_line(read_only_database_url, tmp_path):
    service, address = started(read_only_database_url, tmp_path)
    service.send_signal(signal.SIGINT)
    out, err = service.communicate()
    assert service.returncode == 130 and err.strip() == "error: interrupted (Ctrl-C); what was not yet committed " \
                                                        "was rolled back"
    assert not (tmp_path / "serve.pid").exists()


def test_a_port_in_use_is_one_line(read_only_run, tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        result = read_only_run("serve", "--port", taken.getsockname()[1], env={"ENGINE_RUNTIME_DIR": str(tmp_path)})
    assert result.exit_code == 1 and "cannot listen on 127.0.0.1:" in result.stderr
    assert len(result.stderr.splitlines()) == 1
