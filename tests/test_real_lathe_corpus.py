"""A corpus of lathe programs other people wrote (issue 27), run as they are through the verifier
on the seeded machine of their dialect: verified, or refused naming the construct that stops it.

The files sit byte for byte under tests/data/nc/<source>/ with their origin and open licence in
tests/data/nc/PROVENANCE.tsv. Every lathe program of a chosen source is here, not only the ones
that pass. Each row says whether the refusal is right (a true fault of the file, or a construct
nothing in the file or the machine record can prove: failing closed is what a user relies on) or
a gap (a construct a skilled programmer runs that the engine should learn to prove).

The LinuxCNC files run on `lathe-linuxcnc`: X 0…400 mm, Z −600…200 mm, 4000 r/min."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from helpers.nc_files import DATA as IMPORTABLE
from helpers.real_lathe_corpus import (
    CORPUS,
    GAP,
    RIGHT,
    SOURCES,
)

from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program

DATA = Path(__file__).resolve().parent / "data" / "nc"


def lines_of(name: str) -> list[str]:
    return (DATA / name).read_text(encoding="utf-8").splitlines()


def outcome(conn, machine: str, lines: list[str]) -> str | None:
    """None for a program the verifier reads whole on the seeded `machine`, else its message."""
    try:
        verify_program(lines, load_machine(conn, machine), None)
    except LimitError as error:
        return str(error)
    return None


def test_every_file_of_the_corpus_sources_is_in_the_table():
    present = sorted(str(path.relative_to(DATA)) for source in SOURCES for path in (DATA / source).rglob("*")
                     if path.is_file())
    assert present == sorted(CORPUS)


@pytest.mark.parametrize("name", sorted(CORPUS))
def test_a_real_lathe_program_is_verified_or_refused_naming_its_construct(conn, name):
    machine, construct, _, _ = CORPUS[name]
    message = outcome(conn, machine, lines_of(name))
    if construct is None:
        assert message is None, message
    else:
        assert message is not None and construct in message, message
        assert "\n" not in message and message.endswith("nothing stored")


def test_each_row_says_whether_failing_closed_is_right_or_a_gap():
    assert {kind for _, _, kind, _ in CORPUS.values()} <= {RIGHT, GAP}
    assert all(why and len(why) <= 110 for _, _, _, why in CORPUS.values())


def test_a_cam_path_that_repeats_a_block_imports_but_its_release_is_refused(run):
    """LibLathe wrote each approach rapid twice in a row ('G0 X-20 Y0 Z5 F10' on lines 3 and 4): the
    author's own twin, but the release gate's duplicate-row rule reads each as a row pasted twice.
    A gap of the gate (a verbatim twin from the imported file is not an editor's paste)."""
    lines = lines_of("liblathe/profile.gcode")
    twins = {number + 1 for number in range(1, len(lines))
             if lines[number].strip() and lines[number] == lines[number - 1]}
    imported = run("import-nc", IMPORTABLE / "liblathe" / "profile.gcode", "--class", "liblathe_profile")
    assert imported.exit_code == 0, imported.output
    released = run("template", "release", "--class", "liblathe_profile", "--yes",
                   "--without-golden-tests")
    assert released.exit_code == 1 and "released class" not in released.output
    # import-nc stores line n as row 10·n: the gate names exactly the file's twin lines, the
    # approach rapid of each of its 21 passes (X -20 … 0 in steps of 1)
    named = {int(row) // 10 for row in re.findall(r"row (\d+) column o: repeats row \d+ exactly .{0,60}"
                                                 r"a row pasted twice \(duplicate-row\)", released.output)}
    assert named == twins and len(twins) == 21, released.output
