"""The real lathe programs the verifier accepts (issue 27), followed by the turning simulation on
the stock each is written for, and each one the simulation passes made again from its imported
class with a new value: only the bound word changes, to exactly the value given. One the
simulation refuses is refused when made from its class too, naming its block, nothing stored.

The programs: the LinuxCNC axis lathe macros as their screen calls them (tests/helpers/
linuxcnc_programs.py; go_to_position of tests/helpers/gmoccapy_programs.py), gmoccapy's macros
as gmoccapy runs them, and the Fanuc 0T program FANUC0T.nc on the seeded lathe-fanuc-0t.

A class job's stock is a solid bar (params stock_diameter, stock_z_front, stock_z_back, mm:
engine/simulation/turning/work.py stored_stock): the params hold no bore. The material walk
clears the column radially above a cut (an outside tool's body stands above its tip,
engine/simulation/turning/material.py). So a program that bores (its tool's body inside a
bore) is refused on any stock a class job can state: boring.ngc and FANUC0T.nc. Each refusal
below says whether it is the program's own fault or the stock's, from the program's code."""
from __future__ import annotations

import json
import re
from pathlib import Path

import psycopg
import pytest
from helpers.class_jobs import ok, refused, stored_program
from helpers.linuxcnc_programs import program_of
from helpers.real_programs_made import MADE, REAL, Real

from engine.machines.records import load_machine
from engine.simulation.turning.run import simulate_turning


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("name", sorted(REAL))
def test_each_verified_real_program_is_simulated_on_the_stock_it_is_written_for(conn, name):
    real = REAL[name]
    report = simulate_turning(real.lines(), real.stock, {}, load_machine(conn, real.machine), name)
    findings = [(finding.message, finding.line.strip()) for finding in report.findings]
    if real.refused is None:
        assert findings == [], findings
    else:
        reason, line = real.refused
        assert findings and reason in findings[0][0] and findings[0][1] == line, findings


# --- made again from its imported class with a new value ------------------------------------------------

NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)"


def code_of(line: str) -> str:
    """The line without its comments: ( … ) and from ; on (LinuxCNC and ISO alike)."""
    return re.sub(r"\([^)]*\)", "", line).split(";")[0]


def plain_words(line: str, address: str) -> list[str]:
    """The plain value words at `address` (X1.2, x1.2, F.3; not X#14 nor X[…]) as written."""
    return re.findall(rf"(?<![A-Za-z#<_]){address}\s*{NUMBER}(?![\d.])", code_of(line), re.IGNORECASE)


def value(word: str) -> float:
    return float(re.sub(r"^[A-Za-z]\s*", "", word))


def decimals(word: str) -> int:
    """How many digits the word writes after its decimal point (X10: 0, x1.2: 1)."""
    return len(word.partition(".")[2])


def masked(line: str, address: str) -> str:
    """The line with each plain word at `address` replaced by its letter and '?'."""
    return re.sub(rf"(?<![A-Za-z#<_])({address})\s*{NUMBER}(?![\d.])", r"\1?", line, flags=re.IGNORECASE)


def written(lines: list[str], tmp_path: Path) -> Path:
    """The program as a file import-nc reads: a tab is refused at import, so tabs are written as
    spaces, which LinuxCNC reads alike (a Fanuc file has none and stays as it is)."""
    source = tmp_path / "real.ngc"
    source.write_text("\n".join(line.expandtabs(4) for line in lines) + "\n")
    return source


def imported(run, tmp_path: Path, real: Real) -> tuple[list[str], Path]:
    """(the lines imported as class real_made with the start bound, the params file of the new value)."""
    address, old, new = real.bound
    lines = [line.expandtabs(4) for line in real.lines()]
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"start": {"value": old, "addresses": [address]}}))
    ok(run("import-nc", written(lines, tmp_path), "--class", "real_made", "--params", params))
    values = tmp_path / "new.json"
    values.write_text(json.dumps({"start": new, **real.stock}))
    return lines, values


def made(run, tmp_path: Path, real: Real) -> tuple[list[str], list[str], bool]:
    """(the lines imported, the lines made with the new value, the program's unverified)."""
    lines, values = imported(run, tmp_path, real)
    job = json.loads(ok(run("instantiate", "--class", "real_made", "--machine", real.machine, "--draft",
                            "--params", values, "--json")).stdout)
    made_lines, _, unverified = stored_program(run.url, job["program_id"])
    return lines, made_lines, unverified


@pytest.mark.parametrize("name", MADE)
def test_each_simulated_real_program_made_with_a_new_value_changes_only_its_bound_word(run, tmp_path, name):
    real = REAL[name]
    address, old, new = real.bound
    lines, made_lines, unverified = made(run, tmp_path, real)
    assert not unverified and len(made_lines) == len(lines)
    bound = [n for n, line in enumerate(lines) if any(value(w) == old for w in plain_words(line, address))]
    assert bound, f"{address}{old:g} is not in {name}"
    # the new value has a digit more than the file wrote: the made word carries the value's own digits
    assert all(round(new, decimals(w)) != new for n in bound for w in plain_words(lines[n], address))
    for n, (before, after) in enumerate(zip(lines, made_lines)):
        if n not in bound:
            assert after == before
            continue
        assert masked(after, address) == masked(before, address), (before, after)
        expected = [new if value(w) == old else value(w) for w in plain_words(before, address)]
        assert [value(w) for w in plain_words(after, address)] == expected, (before, after)


def test_the_made_programs_are_the_ones_the_simulation_passes():
    assert MADE == ["gmoccapy/grooving", "gmoccapy/radius", "lathe_macros/chamfer.ngc", "lathe_macros/drill.ngc",
                    "lathe_macros/go_to_position.ngc", "lathe_macros/threading.ngc", "lathe_macros/turning.ngc"]





def programs(url: str) -> int:
    with psycopg.connect(url) as conn:
        row = conn.execute("SELECT count(*) FROM program").fetchone()
    assert row is not None
    return row[0]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("name", sorted(set(REAL) - set(MADE)))
def test_a_real_program_the_simulation_refuses_is_refused_when_made_and_nothing_is_stored(run, tmp_path, name):
    """Imported as a class (the file as the control runs it), it is made on the same stock: the
    simulation names its block and the finding, one line, and no program is stored."""
    real = REAL[name]
    assert real.refused is not None
    _, values = imported(run, tmp_path, real)
    before = programs(run.url)
    message = refused(run("instantiate", "--class", "real_made", "--machine", real.machine, "--draft",
                          "--params", values))
    reason, line = real.refused
    assert reason in message and re.search(rf"line \d+ '\s*{re.escape(line)}\s*'", message), message
    assert message.endswith("nothing stored"), message
    assert programs(run.url) == before


@pytest.mark.parametrize("blank", ["stock_diameter", "stock_z_front", "stock_z_back"])
def test_a_blank_parameter_given_to_import_nc_is_refused_and_no_class_is_stored(read_only_run, tmp_path, blank):
    """The threading macro's G76 ends `e0 l0`: stock_z_front 0 bound at import would make the taper E a
    reference, and a job on another blank would cut another thread. The blank belongs to instantiate."""
    lines = program_of("lathe_macros/threading.ngc")
    source = written(lines, tmp_path)
    params = tmp_path / "params.json"
    params.write_text(json.dumps({blank: 0, "start_x": {"value": 1.2, "addresses": ["X"]}}))
    message = refused(read_only_run("import-nc", source, "--class", "lm_blank", "--params", params))
    assert f"parameter {blank} is the blank of a class job" in message and "instantiate --params" in message
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear_class WHERE name = 'lm_blank'").fetchone() == (0,)
