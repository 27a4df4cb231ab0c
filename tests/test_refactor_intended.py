"""Near-duplicate pairs a person has judged (issue 16): a pair marked intended is no longer listed by
the nightly refactor, only counted; pairs no earlier run listed come first, marked new; who marked
a pair, as which role, why and when are stored; bad marks are refused with one line."""
from __future__ import annotations

import csv
import io
import json

import psycopg
import pytest
from helpers.roles import as_role

from engine.errors import EngineError
from engine.library.intended import intend, intents, unintend
from engine.library.refactor import refactor
from engine.templates.rows import TemplateRow
from engine.templates.store import ensure_class, replace_template

# Seeded coupling lines: the worm wheel couples Y, helical, taper and crowned couple Z. Their NC units
# differ in one of 12 (Sim = 11/13 ≥ 0.8), so the seeded library reports this pair at 0.8.
Y_COUPLING, Z_COUPLING = '"EGDEF(C,B,1,Y,1)"', '"EGDEF(C,B,1,Z,1)"'
X_COUPLING = '"EGDEF(C,B,1,X,1)"'   # not seeded: one unit from each of them


def texts(pair: dict) -> frozenset:
    return frozenset((pair["a"], pair["b"]))


def find(report_pairs: list[dict], *pair_texts: str) -> dict:
    return next(pair for pair in report_pairs if texts(pair) == frozenset(pair_texts))


def add_x_coupling(conn) -> None:
    """A new class whose coupling line is a near-duplicate of both seeded couplings."""
    ensure_class(conn, "x_coupled")
    replace_template(conn, "x_coupled", [TemplateRow(1400, "sync", 1, None, None, X_COUPLING, None)])


def intended_rows(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM near_duplicate_intended").fetchone()[0]


def test_a_pair_marked_intended_is_not_listed_next_run_and_is_counted(conn):
    first = refactor(conn)
    pair = find(first.near_duplicates, Y_COUPLING, Z_COUPLING)
    intend(conn, "the worm wheel couples Y (tangential feed), the others Z", key=pair["key"])

    second = refactor(conn)

    assert all(texts(listed) != texts(pair) for listed in second.near_duplicates)
    assert second.intended == 1
    assert len(second.near_duplicates) == len(first.near_duplicates) - 1
    assert second.new + second.known == len(second.near_duplicates)
    assert second.as_dict()["intended"] == 1


def test_a_second_run_lists_a_new_near_duplicate_first_and_the_rest_as_known(conn):
    first = refactor(conn)
    assert first.new == len(first.near_duplicates) > 0 and first.known == 0   # nothing reported before
    assert all(pair["new"] for pair in first.near_duplicates)
    add_x_coupling(conn)

    second = refactor(conn).as_dict()

    fresh = [pair for pair in second["near_duplicates"] if X_COUPLING in texts(pair)]
    assert {frozenset(texts(pair) - {X_COUPLING}) for pair in fresh} == {frozenset({Y_COUPLING}),
                                                                          frozenset({Z_COUPLING})}
    assert second["near_duplicates"][:len(fresh)] == fresh              # the new pairs come first
    assert all(pair["new"] is True for pair in fresh)
    assert all(pair["new"] is False for pair in second["near_duplicates"][len(fresh):])
    assert (second["new"], second["known"]) == (2, len(first.near_duplicates))
    assert refactor(conn).new == 0                                       # a third run: all known


def test_a_pair_keeps_its_key_across_runs_and_either_order_of_its_texts(conn):
    key = find(refactor(conn).near_duplicates, Y_COUPLING, Z_COUPLING)["key"]
    assert find(refactor(conn).near_duplicates, Y_COUPLING, Z_COUPLING)["key"] == key
    mark = intend(conn, "kept apart on purpose", texts=(Z_COUPLING, Y_COUPLING))   # the texts swapped
    assert mark.key == key and mark.t == "sync"


def test_who_role_why_and_when_are_stored(conn):
    login = conn.execute("SELECT session_user").fetchone()[0]
    refactor(conn)
    with as_role(conn, "engine_editor"):
        mark = intend(conn, "  Y is the worm wheel's tangential axis  ", texts=(Y_COUPLING, Z_COUPLING))
    stored = conn.execute("SELECT marked_by, marked_role, why, marked_at = now() FROM near_duplicate_intended "
                          "WHERE withdrawn_at IS NULL").fetchall()
    assert stored == [(login, "engine_editor", "Y is the worm wheel's tangential axis", True)]
    assert [m.as_dict() for m in intents(conn)] == [mark.as_dict()]


def test_unintend_lists_the_pair_again_as_known_and_keeps_the_withdrawn_mark(conn):
    pair = find(refactor(conn).near_duplicates, Y_COUPLING, Z_COUPLING)
    intend(conn, "for now", key=pair["key"])
    assert refactor(conn).intended == 1
    with as_role(conn, "engine_editor"):
        unintend(conn, pair["key"])
    again = refactor(conn)
    listed = find(again.near_duplicates, Y_COUPLING, Z_COUPLING)
    assert (listed["key"], listed["new"], again.intended) == (pair["key"], False, 0)
    assert intents(conn) == []
    assert conn.execute("SELECT withdrawn_role FROM near_duplicate_intended").fetchall() == [("engine_editor",)]


def test_roles_editors_mark_readers_do_not_runners_remember(conn):
    key = find(refactor(conn).near_duplicates, Y_COUPLING, Z_COUPLING)["key"]
    with pytest.raises(psycopg.errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_reader"):
        intend(conn, "a reader may not decide this", key=key)
    with pytest.raises(psycopg.errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_runner"):
        intend(conn, "nor may a runner", key=key)
    with conn.transaction(), as_role(conn, "engine_runner"):
        conn.execute("INSERT INTO near_duplicate_seen (pair_key, t, a, b) VALUES (repeat('0', 64), 'main', 'x', 'y')")
    with pytest.raises(psycopg.errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_editor"):
        conn.execute("UPDATE near_duplicate_intended SET why = 'rewritten'")


def test_texts_that_are_lines_of_two_module_types_need_the_type(conn):
    ensure_class(conn, "two_types")
    replace_template(conn, "two_types", [TemplateRow(row_id, t, 1, None, None, text, None)
                                         for row_id, t, text in ((100, "main", '"G0 X1 Z5"'),
                                                                 (110, "main", '"G0 X1 Z6"'),
                                                                 (1200, "prep", '"G0 X1 Z5"'),
                                                                 (1210, "prep", '"G0 X1 Z6"'))])
    with pytest.raises(EngineError, match="module types main, prep; choose one with --type"):
        intend(conn, "notes", texts=('"G0 X1 Z5"', '"G0 X1 Z6"'))
    mark = intend(conn, "notes", texts=('"G0 X1 Z5"', '"G0 X1 Z6"'), t="prep")
    assert mark.t == "prep"
    with pytest.raises(EngineError, match="module type 'sync'"):
        intend(conn, "notes", texts=('"G0 X1 Z5"', '"G0 X1 Z6"'), t="sync")
    listed = refactor(conn, threshold=0.5)
    assert [pair["t"] for pair in listed.near_duplicates if texts(pair) == {'"G0 X1 Z5"', '"G0 X1 Z6"'}] == ["main"]
    assert listed.intended == 1


@pytest.mark.parametrize("why, key, pair_texts, words", [
    ("   ", None, (Y_COUPLING, Z_COUPLING), "--why is empty"),
    ("ok", "0123456789ab", None, "not among the pairs a refactor run reported"),
    ("ok", "G01", None, "is not a key"),
    ("ok", None, (Y_COUPLING, '"NO SUCH LINE"'), "not both lines"),
    ("ok", None, (Y_COUPLING, Y_COUPLING), "the same text"),
    ("ok", None, None, "name the pair"),
])
def test_bad_marks_are_refused_and_store_nothing(conn, why, key, pair_texts, words):
    refactor(conn)
    with pytest.raises(EngineError, match=words):
        intend(conn, why, key=key, texts=pair_texts)
    assert intents(conn) == []


def test_cli_report_json_is_one_line_with_keys_new_flags_and_counts(run):
    first = run("refactor", "--json")
    assert first.exit_code == 0, first.output
    assert len(first.stdout.splitlines()) == 1
    report = json.loads(first.stdout)
    assert (report["new"], report["known"], report["intended"]) == (len(report["near_duplicates"]), 0, 0)
    key = find(report["near_duplicates"], Y_COUPLING, Z_COUPLING)["key"]

    marked = run("refactor", "intend", key, "--why", "worm wheel: Y")
    assert marked.exit_code == 0, marked.output
    assert key in marked.stdout
    text = run("refactor")
    assert text.exit_code == 0
    assert "1 marked intended, not listed" in text.stdout and key not in text.stdout
    with psycopg.connect(run.url) as conn:
        add_x_coupling(conn)
    after = json.loads(run("refactor", "--json").stdout)
    assert [pair["new"] for pair in after["near_duplicates"]] == \
        [True] * after["new"] + [False] * after["known"]
    assert after["intended"] == 1 and after["new"] == 2   # X against Y and against Z


def test_cli_intents_lists_json_and_csv_and_unintend_withdraws(run):
    key = find(json.loads(run("refactor", "--json").stdout)["near_duplicates"], Y_COUPLING, Z_COUPLING)["key"]
    assert run("refactor", "intend", "--a", Y_COUPLING, "--b", Z_COUPLING, "--why", "Y, Z: tangential").exit_code == 0
    as_json = run("refactor", "intents", "--json")
    assert len(as_json.stdout.splitlines()) == 1
    [mark] = json.loads(as_json.stdout)["intents"]
    assert (mark["key"], mark["t"], mark["why"], {mark["a"], mark["b"]}) == \
        (key, "sync", "Y, Z: tangential", {Y_COUPLING, Z_COUPLING})
    [row] = list(csv.DictReader(io.StringIO(run("refactor", "intents", "--csv").stdout)))
    assert (row["key"], row["why"], row["a"], row["b"]) == (key, "Y, Z: tangential", mark["a"], mark["b"])
    assert run("refactor", "unintend", key).exit_code == 0
    withdrawn = run("refactor", "intents")
    assert withdrawn.stdout.splitlines() == ["key  t  a  b  why  marked_by  marked_role  marked_at"]
    assert withdrawn.stderr.strip() == "0 intents"


@pytest.mark.parametrize("args, words", [
    (("intend", "0123456789ab", "--why", "x"), "not among the pairs a refactor run reported"),
    (("intend", "--a", Y_COUPLING, "--b", Z_COUPLING, "--why", ""), "--why is empty"),
    (("intend", "--a", Y_COUPLING, "--why", "x"), "name the pair"),
    (("unintend", "0123456789ab"), "not among the pairs marked intended"),
    (("intents", "--json", "--csv"), "--json and --csv"),
])
def test_cli_refusals_are_one_line_exit_1_and_store_nothing(read_only_run, args, words):
    result = read_only_run("refactor", *args)
    assert result.exit_code == 1
    assert result.stdout == ""
    assert len(result.stderr.splitlines()) == 1 and words in result.stderr
    assert intended_rows(read_only_run.url) == 0


def test_cli_marking_a_marked_pair_again_is_refused(run):
    assert run("refactor", "intend", "--a", Y_COUPLING, "--b", Z_COUPLING, "--why", "first").exit_code == 0
    again = run("refactor", "intend", "--a", Z_COUPLING, "--b", Y_COUPLING, "--why", "second")
    assert again.exit_code == 1 and "marked intended already" in again.stderr and "first" in again.stderr
    assert intended_rows(run.url) == 1


@pytest.mark.parametrize("command", ["refactor", "intend", "intents", "unintend"])
def test_help_has_an_example(read_only_run, command):
    args = ("refactor", "--help") if command == "refactor" else ("refactor", command, "--help")
    result = read_only_run(*args)
    assert result.exit_code == 0
    assert any(line.strip().startswith("Example: engine refactor") for line in result.stdout.splitlines())
