"""The web view in a real browser (issue 32): the distribution's Chromium, driven by Playwright,
does what an operator does at the control. It opens gear 42's program page, follows an NC line
to why it is there, looks the program up by the hash on its lineage line from the search box, and
sees the plot drawn (an SVG with paths, of a size on the screen). A missing Chromium fails the
test with what to install: a browser test skipped is a browser test not run."""
from __future__ import annotations

import json
import os
import re
import socket
import threading
import time
from pathlib import Path

import pytest

from engine.service.web.app import create_app

CHROMIUM = Path(os.environ.get("ENGINE_TEST_CHROMIUM", "/usr/bin/chromium"))
GEAR = 42
SPINDLE_LINE = "M3 S246"        # the paper's n0 = 246 r/min for gear 42 (tests/test_serve_web.py)
SPINDLE_ROW = 1700
START_SECONDS = 30              # how long the server may take to start on a busy machine (not asserted)
SCREENSHOTS = "ENGINE_TEST_SCREENSHOTS"   # a folder to keep the screenshots in (else the test's tmp_path)


@pytest.fixture
def served(run):
    """(address, program id, input hash) of gear 42's program, the web view serving its database
    with uvicorn in a thread of the test."""
    import uvicorn

    made = run("instantiate", "--gear", GEAR, "--json")
    assert made.exit_code == 0, made.output
    program_id = json.loads(made.stdout)["program_id"]
    digest = json.loads(run("programs", "show", program_id, "--json").stdout)["programs"][0]["input_hash"]
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(create_app(run.url), host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + START_SECONDS
    while not server.started:
        assert thread.is_alive() and time.monotonic() < deadline, "the web view did not start"
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}", program_id, digest
    server.should_exit = True
    thread.join()


@pytest.fixture
def browser():
    if not CHROMIUM.is_file():
        pytest.fail(f"no Chromium at {CHROMIUM}: install Debian's `chromium` (apt-get install chromium; .ci/run "
                    "does) or name one with ENGINE_TEST_CHROMIUM; this test is not skipped", pytrace=False)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=str(CHROMIUM), args=["--no-sandbox"])
        yield launched
        launched.close()


@pytest.mark.slow   # a real Chromium: seconds; every full run and CI leg runs it (issue 28: test-fast)
def test_an_operator_finds_a_program_its_trace_and_its_plot_in_a_browser(served, browser, tmp_path):
    address, program_id, digest = served
    shots = Path(os.environ.get(SCREENSHOTS) or tmp_path)
    shots.mkdir(parents=True, exist_ok=True)
    page = browser.new_page(viewport={"width": 1280, "height": 900})

    page.goto(f"{address}/gears/{GEAR}")
    page.get_by_role("link", name=f"Programs of gear {GEAR}").click()
    page.locator(f'a[href="/programs/{program_id}"]').first.click()
    page.wait_for_url(f"{address}/programs/{program_id}")
    assert page.locator("#status").inner_text() == "MATCH"
    assert page.locator("#program-text").get_by_text(f"; PROGRAM {program_id} TEMPLATE spur v1").count() == 1
    plot = page.locator("#plot svg")
    box = plot.bounding_box()
    assert box is not None and box["width"] > 100 and box["height"] > 50
    assert plot.locator("path").count() > 0
    page.screenshot(path=str(shots / "program.png"), full_page=True)

    page.locator("#program-text a", has_text=re.compile(f"^{SPINDLE_LINE}$")).click()
    page.wait_for_url(f"{address}/programs/{program_id}/rows/{SPINDLE_ROW}")
    assert f"{SPINDLE_ROW} {SPINDLE_LINE} emitted: n0 = 246 (job)" in page.locator(".sentence").inner_text()
    assert page.locator("table.values td", has_text="n0").count() == 1
    page.screenshot(path=str(shots / "trace.png"), full_page=True)

    page.get_by_label("look up a program").fill(digest[:8])
    page.get_by_role("button", name="Look up").click()
    page.wait_for_url(f"{address}/programs/{program_id}")
    assert page.locator("#status").inner_text() == "MATCH"
    page.screenshot(path=str(shots / "lookup.png"))
