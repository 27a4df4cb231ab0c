"""Where a refusal's other findings are listed (new-user review 29): a program the simulation
refuses before it is stored is simulated by no command afterwards, so its refusal counts the other
findings without pointing anywhere; `engine simulate` lists every finding of a stored program,
also one the proof a new program gets refuses now (records changed since it was stored), and its
error line says they are listed above. The seeded machine's fixture and tailstock are enlarged to
Ø300 after gear 42's program is stored: the hob runs into both (more than one finding)."""
from __future__ import annotations

import json

import psycopg
import pytest

from engine.simulation.hobbing.report import Report

ENLARGE = "UPDATE machine SET fixture_diameter = 300, tailstock_diameter = 300"


def test_a_refusal_counts_the_other_findings_without_naming_a_command():
    report = Report("GEAR7")
    report.add(10, "G0 X1", "the hob runs into the fixture")
    report.add(11, "G0 X2", "the hob runs into the tailstock")
    message = str(report.error())
    assert message.endswith("(and 1 more finding)") and "engine simulate" not in message


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_engine_simulate_lists_every_finding_of_a_program_refused_now(run):
    made = run("instantiate", "--gear", 42, "--json")
    program_id = json.loads(made.stdout)["program_id"]
    with psycopg.connect(run.url) as conn:
        conn.execute(ENLARGE)
    shown = run("simulate", "--program", program_id)
    assert shown.exit_code == 1
    refused = [line for line in shown.stdout.splitlines() if line.startswith("refused: ")]
    assert len(refused) > 1 and any("tailstock" in line for line in refused) and \
        any("into the fixture" in line for line in refused)
    assert shown.stderr.count("\n") == 1 and "REFUSED" in shown.stderr, "the proof a new program gets refuses it"
    assert "the simulation's findings are listed above" in shown.stderr and "engine simulate" not in shown.stderr
    payload = run("simulate", "--program", program_id, "--json")
    assert len([f for f in json.loads(payload.stdout)["findings"] if f["refuses"]]) == len(refused)


def test_an_unstored_program_points_to_no_command(run):
    with psycopg.connect(run.url) as conn:
        conn.execute(ENLARGE)
    refused = run("instantiate", "--gear", 42, "--no-tailstock")
    assert refused.exit_code == 1, refused.output
    # a program refused before it is stored is refused at its first finding (the search tries the
    # next choice at once, issue 28): the finding is named, no count and no command to list more
    assert "the simulation refuses GEAR42 line " in refused.stderr and "more finding" not in refused.stderr
    assert refused.stderr.count("\n") == 1
    assert "engine simulate" not in refused.stderr and "nothing stored" in refused.stderr
