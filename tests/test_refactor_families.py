"""Near-duplicates that differ only in the block number are one family (issue 17): the 840D CAM
program of tests/data repeats `N460 G0 Z60.`, `N1430 G0 Z60.`, … after every contour; the
nightly refactor lists them once, with every member, not once per pair. A family has a key that
stays when members join, and marking it intended keeps it out of the report. What the tests
expect is read off the program's text here (its lines without their block number)."""
from __future__ import annotations

import hashlib
import json
import re
from collections import defaultdict

import psycopg
import pytest
from click.testing import CliRunner
from helpers.nc_files import DATA
from helpers.outcomes import made

from engine.cli.app import main
from engine.errors import EngineError
from engine.library.intended import intend, intents, shown_key, unintend
from engine.library.nc_import import import_nc
from engine.library.refactor import refactor

CAM = DATA / "sinumerik/cam_840dsl/CAM_TEST.MPF"
BLOCK_NUMBER = re.compile(r"^N\d+ *")
RETRACT = "G0 Z60."                                                            # 28 times in the program
ARCS = ("G3 X68.766 Y95.751 I4.25 J0.", "G3 X68.766 Y95.75 I4.25 J0.")   # 2 and 6 times: Sim 0.8


def program_lines(path=CAM) -> list[str]:
    return path.read_text().splitlines()


def rows(conn, gear_class: str) -> dict[int, tuple[str, str]]:
    """Line number → (module type, stored o) of the class's rows."""
    return {row_id // 10: (t, o) for row_id, t, o in conn.execute(
        "SELECT a.id, c.t, c.o FROM assembly a JOIN component c ON c.id = a.component_id "
        "WHERE a.gear_class = %s", (gear_class,))}


def expected_families(conn, gear_class: str, path=CAM) -> dict[tuple[str, str], set[str]]:
    """(module type, line without its block number) → the stored texts of its lines, where
    lines differing only in their block number have more than one text."""
    stored = rows(conn, gear_class)
    groups = defaultdict(set)
    for number, line in enumerate(program_lines(path), start=1):
        t, o = stored[number]
        groups[(t, BLOCK_NUMBER.sub("", line))].add(o)
    return {key: texts for key, texts in groups.items() if len(texts) > 1}


def families_of(report, texts: set[str]) -> list[dict]:
    return [entry for entry in report.near_duplicates if entry["kind"] == "family" and set(entry["members"]) <= texts]


def family_of(report, line: str) -> dict:
    return next(entry for entry in report.near_duplicates
                if entry["kind"] == "family" and BLOCK_NUMBER.sub("", entry["a"][1:-1]) == line)


def test_lines_differing_only_in_the_block_number_are_one_family_with_every_member(conn):
    import_nc(conn, CAM, "cam")
    expected = expected_families(conn, "cam")
    report = refactor(conn)
    cam_texts = {o for _, o in rows(conn, "cam").values()}
    assert {(entry["t"], frozenset(entry["members"])) for entry in families_of(report, cam_texts)} == \
        {(t, frozenset(texts)) for (t, _), texts in expected.items()}
    retract = family_of(report, RETRACT)
    assert len(retract["members"]) == sum(1 for line in program_lines() if BLOCK_NUMBER.sub("", line) == RETRACT)
    assert retract["uses"] == len(retract["members"]) and retract["sim"] == 1.0
    family_texts = [set(texts) for texts in expected.values()]
    assert not [entry for entry in report.near_duplicates if entry["kind"] == "pair" and any(
        {entry["a"], entry["b"]} <= texts for texts in family_texts)]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_two_families_of_near_duplicate_lines_are_one_pair_listing_their_members(conn):
    import_nc(conn, CAM, "cam")
    members = [{f'"{line}"' for line in program_lines() if BLOCK_NUMBER.sub("", line) == arc} for arc in ARCS]
    assert [len(texts) for texts in members] == [2, 6]
    report = refactor(conn)
    between = [entry for entry in report.near_duplicates if entry["kind"] == "pair" and
               {entry["a"], entry["b"]} & members[0] and {entry["a"], entry["b"]} & members[1]]
    assert len(between) == 1
    pair = between[0]
    assert {frozenset(pair["members_a"]), frozenset(pair["members_b"])} == {frozenset(texts) for texts in members}
    assert {pair["uses_a"], pair["uses_b"]} == {2, 6}


def renumbered(tmp_path, old: str, new: str):
    """The CAM program with one block number changed: the family of that line gains a member."""
    lines = program_lines()
    index = lines.index(old)
    lines[index] = new
    path = tmp_path / "CAM_RENUMBERED.MPF"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_family_keeps_its_key_when_a_member_joins_and_marked_intended_is_not_listed(conn, tmp_path):
    import_nc(conn, CAM, "cam")
    first = family_of(refactor(conn), RETRACT)
    member = first["members"][0][1:-1]
    joining = BLOCK_NUMBER.sub(lambda match: f"N{int(match.group().strip()[1:]) + 5} ", member)
    import_nc(conn, renumbered(tmp_path, member, joining), "cam_renumbered")
    second = family_of(refactor(conn), RETRACT)
    assert second["key"] == first["key"] and set(second["members"]) == set(first["members"]) | {f'"{joining}"'}
    intend(conn, "the retract after every contour", key=second["key"])
    third = refactor(conn)
    assert third.intended == 1
    assert not [entry for entry in third.near_duplicates if entry["kind"] == "family" and
                BLOCK_NUMBER.sub("", entry["a"][1:-1]) == RETRACT]


def test_two_member_texts_name_their_family(conn):
    import_nc(conn, CAM, "cam")
    family = family_of(refactor(conn), RETRACT)
    mark = intend(conn, "the retract after every contour", texts=(family["members"][-1], family["members"][1]))
    assert mark.key == family["key"]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_command_prints_a_family_once_with_its_size(fresh_database_url):
    def run(*args):
        return CliRunner().invoke(main, ["--database-url", fresh_database_url, *map(str, args)])
    assert run("import-nc", CAM, "--class", "cam").exit_code == 0
    result = run("refactor")
    assert result.exit_code == 0, result.output
    size = sum(1 for line in program_lines() if BLOCK_NUMBER.sub("", line) == RETRACT)
    headers = [line for line in result.stdout.splitlines()
               if f"{size} lines differing only in the block number" in line]
    assert len(headers) == 1
    # first 10 members
    assert sum(1 for line in result.stdout.splitlines() if line.strip().endswith(f' {RETRACT}"')) == 10


def key_of_full_texts(t: str, a: str, b: str) -> str:
    """The key a pair was stored under before issue 17: sha256 of [t, the two texts, block numbers
    included, sorted] as JSON."""
    return hashlib.sha256(json.dumps([t, *sorted((a, b))], ensure_ascii=True).encode("ascii")).hexdigest()


def marked_before_issue_17(conn, t: str, a: str, b: str, why: str) -> str:
    key = key_of_full_texts(t, a, b)
    conn.execute("INSERT INTO near_duplicate_intended (pair_key, t, a, b, why) VALUES (%s, %s, %s, %s, %s)",
                 (key, t, *sorted((a, b)), why))
    return key


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_marks_and_seen_pairs_stored_before_block_numbers_left_the_keys_still_hold(conn):
    """A shop marked two retracts (one family now) and two arcs (one pair of families now)
    intended, under the keys of their full texts; the report still leaves both out and counts
    them, the marks keep their key and who made them, and withdrawing one lists it again."""
    import_nc(conn, CAM, "cam")
    t_of = {o: t for t, o in rows(conn, "cam").values()}
    retracts = sorted(f'"{line}"' for line in program_lines() if BLOCK_NUMBER.sub("", line) == RETRACT)[:2]
    arcs = [next(f'"{line}"' for line in program_lines() if BLOCK_NUMBER.sub("", line) == arc) for arc in ARCS]
    old_keys = [marked_before_issue_17(conn, t_of[texts[0]], *texts, "meant") for texts in (retracts, arcs)]
    report = refactor(conn)
    assert report.intended == 2
    assert not [entry for entry in report.near_duplicates if set(retracts) <= listed(entry) or
                set(arcs) <= listed(entry)]
    assert sorted(mark.key for mark in intents(conn)) == sorted(shown_key(key) for key in old_keys)
    with pytest.raises(EngineError, match="marked intended already"):
        intend(conn, "again", texts=tuple(retracts))
    unintend(conn, old_keys[1])
    again = refactor(conn)
    assert again.intended == 1 and len([entry for entry in again.near_duplicates if set(arcs) <= listed(entry)]) == 1


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_pair_listed_before_block_numbers_left_the_keys_is_not_new(conn):
    import_nc(conn, CAM, "cam")
    t_of = {o: t for t, o in rows(conn, "cam").values()}
    arcs = [next(f'"{line}"' for line in program_lines() if BLOCK_NUMBER.sub("", line) == arc) for arc in ARCS]
    conn.execute("INSERT INTO near_duplicate_seen (pair_key, t, a, b) VALUES (%s, %s, %s, %s)",
                 (key_of_full_texts(t_of[arcs[0]], *arcs), t_of[arcs[0]], *sorted(arcs)))
    report = refactor(conn)
    assert [entry["new"] for entry in report.near_duplicates if set(arcs) <= listed(entry)] == [False]
    assert report.new == len(report.near_duplicates) - 1


def listed(entry: dict) -> set:
    return set(entry.get("members") or entry["members_a"] + entry["members_b"])


def key_before_issue_17(t: str, a: str, b: str) -> str:
    """The key `engine refactor intend` stored for a pair before issue 17: sha256 of
    [t, the two full texts sorted] as JSON (the texts with their block numbers)."""
    return hashlib.sha256(json.dumps([t, *sorted((a, b))], ensure_ascii=True).encode("ascii")).hexdigest()


def members(entry: dict) -> set:
    """The texts a report entry lists: a family's members, or both sides of a pair."""
    return set(entry.get("members") or entry["members_a"] + entry["members_b"])


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_pair_marked_intended_before_the_upgrade_stays_intended(run):
    """A shop marked `N90 SUPA … D1` / `N140 SUPA … D1` intended (homing twice is meant) before
    issue 17. Since block numbers are left out of the keys, the mark's key matches nothing:
    the two lines come back in the nightly report, flagged NEW, as if nobody had decided."""
    imported = run("import-nc", CAM, "--class", "cam")
    assert imported.exit_code == 0, imported.output
    a = '"N90 SUPA X=_X_HOME Y=_Y_HOME A=_A_HOME C=_C_HOME D1"'
    b = '"N140 SUPA X=_X_HOME Y=_Y_HOME A=_A_HOME C=_C_HOME D1"'
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(DISTINCT o) FROM component WHERE o IN (%s, %s)", (a, b)).fetchone()[0] == 2
        conn.execute("INSERT INTO near_duplicate_intended (pair_key, t, a, b, why) VALUES (%s, 'prep', %s, %s, "
                     "'homing twice is meant')", (key_before_issue_17("prep", a, b), *sorted((a, b))))
    report = made(run("refactor", "--threshold", "0.6", "--json"))
    listed = [entry for entry in report["near_duplicates"] if {a, b} <= members(entry)]
    assert listed == [] and report["intended"] >= 1
