"""Hostile template rows (issue 13): every one is refused in one line with exit code 1 and stores
nothing, within the instantiation's budget of bytes. Each enters the way a careless or hostile
editor would, through the template view in SQL (into the draft), and the editor's `engine instantiate
--draft` runs in a process whose address space is limited (RLIMIT_AS) to a few times what an
instantiation needs: a row that
allocated its gigabyte would die there of MemoryError (exit 2), not be refused. `engine lint`
names every row the gate can judge without a job, and goes on to the next class."""
import json
import os
import resource
import subprocess
import sys
import tracemalloc
from pathlib import Path

import psycopg
import pytest

from engine.templates.budget import MAX_BYTES
from engine.templates.checks import structural_problems
from engine.templates.decision_table import CompiledTemplate, TemplateError, compile_row, rows_compiled_once
from engine.templates.expressions import MAX_EXPRESSION_LENGTH
from engine.templates.rows import Template, TemplateRow
from engine.templates.trace import MAX_TRACE_BYTES
from engine.turning.moves import Move

ROOT = Path(__file__).resolve().parents[1]
ADDRESS_SPACE = 384 << 20     # an instantiation of gear 42 needs about 60 MiB of address space
ROW = 750                     # a new row of spur's main module, between 700 and 800
RUNTIME = "z2 > 0"            # true for every gear, but only a job can say so: the gate cannot evaluate it
WIDE = f"(({RUNTIME}) * 65536)"
DEEP = 45                     # nesting levels (the gate allows 40)

# (s, o, p_emit), words of the refusal, and whether the gate sees it without a job (then lint names it)
HOSTILE = [
    ((None, "f'{[[0] * 65536] * 65536 == [[0] * 65536] * 65536}'", None), "larger than 65536", True),
    ((None, f"f'{{[[0] * {WIDE}] * {WIDE} == [[0] * {WIDE}] * {WIDE}}}'", None), "larger than 65536", False),
    ((None, "[[0] * 65536] * 65536", None), "larger than 65536", True),
    ((f"o = [[0] * {WIDE}] * {WIDE}", "'x'", None), "larger than 65536", False),
    ((None, "b'a' * 10 ** 9", None), "bytes literals are not allowed", True),
    ((None, "b'%2000000000d' % 0", None), "bytes literals are not allowed", True),
    ((None, "'%2000000000d' % z2", None), "use an f-string", True),
    ((None, "-" * 3000 + "z2", None), "nested too deeply", True),
    ((None, "[" * DEEP + "z2" + "]" * DEEP, None), "nested too deeply", True),
    ((None, "abs(" * DEEP + "z2" + ")" * DEEP, None), "nested too deeply", True),
    ((None, "'x'", "NOT " * DEEP + "z2 = 1"), "nested too deeply", True),
    (("_sql_truth = 1", "'x'", None), "reserved", True),
    (("template_version = 1", "'x'", None), "name of the engine", True),
    ((None, "f'{10 ** 10 ** 6}'", None), "power too large", True),
    (("a = z2 ** 10 ** 6", "'x'", None), "power too large", False),
    ((None, f"'x' * ({RUNTIME}) * 10 ** 9", None), "repetition larger", False),
    ((f"a = 'x' * {WIDE}; b = a + a", "'x'", None), "larger than 65536", False),
    ((f"w = ({RUNTIME}) * 10 ** 9", "f'{z2:>{w}}'", None), "format width", False),
    ((None, f"f'{{[z2] * {WIDE}}}'", None), "a list cannot be printed", False),
    ((None, f"str([z2] * {WIDE})", None), "a list cannot be printed", False),
    ((None, "f'{int(\"9\" * 4300)}'", None), "longer than 4096", True),
    ((f"a = 'a' * {WIDE}", "'x'", "a LIKE '%" + "_" * 990 + "b%'"), "steps", False),
    # cheap one statement at a time, a copy of 256 KiB each (4-byte characters): the run's bytes run out
    ((f"c = '\U0001F600' * {WIDE};" + ";".join(f"a{k}=c[1:]" for k in range(300)), "'x'", None),
     "MiB in one instantiation", False),
]


def counts(conn):
    return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


def limited_address_space():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


def engine(url, *args):
    environment = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "engine", "--database-url", url, *args], capture_output=True,
                          text=True, env=environment, preexec_fn=limited_address_space, timeout=120)


def put_row(conn, gear_class, row_id, columns):
    s, o, p_emit = columns
    conn.execute("DELETE FROM template_view WHERE gear_class = %s AND id = %s", (gear_class, row_id))
    conn.execute("INSERT INTO template_view (gear_class, id, t, n, s, o, p_emit) "
                 "VALUES (%s, %s, 'main', 1, %s, %s, %s)",
                 (gear_class, row_id, s, o, p_emit))


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_an_ordinary_instantiation_fits_the_address_space_the_hostile_rows_get(fresh_database_url):
    done = engine(fresh_database_url, "instantiate", "--gear", "42")
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("columns, words, seen", HOSTILE, ids=lambda value: str(value)[:50] if isinstance(value, tuple)
                         else None)
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_hostile_row_in_the_template_view_is_refused_in_one_line(fresh_database_url, columns, words, seen):
    with psycopg.connect(fresh_database_url) as conn:
        put_row(conn, "spur", ROW, columns)
        conn.commit()
        before = counts(conn)
    refused = engine(fresh_database_url, "instantiate", "--gear", "42", "--draft")   # the editor tries the draft
    assert refused.returncode == 1, refused.stderr
    assert refused.stderr.count("\n") == 1 and len(refused.stderr) < 700
    assert refused.stderr.startswith(f"error: class spur row {ROW} column ") and words in refused.stderr
    with psycopg.connect(fresh_database_url) as conn:
        assert counts(conn) == before


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_lint_names_every_row_the_gate_refuses_and_goes_on(fresh_database_url):
    seen = [columns for columns, _, gate_sees in HOSTILE if gate_sees]
    with psycopg.connect(fresh_database_url) as conn:
        for number, columns in enumerate(seen):
            put_row(conn, "spur" if number % 2 else "helical", ROW + number, columns)
        conn.commit()
    linted = engine(fresh_database_url, "lint")
    assert linted.returncode == 1, linted.stderr
    named = {line.split(" column ")[0] for line in linted.stdout.splitlines()}
    expected = {f"class {'spur' if number % 2 else 'helical'} row {ROW + number}" for number in range(len(seen))}
    assert expected <= named
    assert "class duplex" in linted.stdout   # duplex inherits spur's rows: lint went on past spur


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_rows_cheap_alone_stop_at_the_budget_of_the_whole_run(fresh_database_url):
    """Each row prints one line of 256 KiB; 300 of them are more than one run may build."""
    line = f"'\U0001F600' * {WIDE}"
    with psycopg.connect(fresh_database_url) as conn:
        for row_id in [*range(701, 800), *range(801, 900), *range(901, 1000), *range(1001, 1004)]:
            put_row(conn, "spur", row_id, (None, line, None))
        conn.commit()
        before = counts(conn)
    refused = engine(fresh_database_url, "instantiate", "--gear", "42", "--draft")   # the editor tries the draft
    assert refused.returncode == 1 and refused.stderr.count("\n") == 1, refused.stderr
    assert f"more than {MAX_BYTES >> 20} MiB in one instantiation" in refused.stderr
    with psycopg.connect(fresh_database_url) as conn:
        assert counts(conn) == before


def run_traced(rows, params, seconds=2.0):
    """The refusal of a template, and the most memory Python held while it ran."""
    template = CompiledTemplate(Template("hostile", 1, tuple(TemplateRow(10 * k + 10, "main", 1, None, s, o, p_emit)
                                                             for k, (s, o, p_emit) in enumerate(rows))))
    tracemalloc.start()
    try:
        with pytest.raises(TemplateError) as refused:
            template.run(params, deadline_seconds=seconds)
        return str(refused.value), tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_tool_paths_are_paid_block_by_block():
    """nc_path prints up to 200,000 blocks of 512 characters: two calls on a path of 65,000
    copies of one move would build 70 MB; the second stops when the run's bytes run out."""
    wide = "'X{x}" + "0" * 500 + "'"
    rows = [(f"f = {wide}; m = [moves[0]] * 65000", "(nc_path(m, f, f, f, f, f), nc_path(m, f, f, f, f, f))", None)]
    message, peak = run_traced(rows, {"moves": [Move("feed", 1.0, 2.0)]}, seconds=600)   # tracemalloc is slow
    assert f"more than {MAX_BYTES >> 20} MiB in one instantiation" in message
    assert peak < MAX_BYTES + (16 << 20)


def test_a_long_tool_path_stops_at_the_deadline_between_blocks():
    rows = [("f = 'X{x:200.190f}'; m = [moves[0]] * 65000", "nc_path(m, f, f, f, f, f)", None)]
    template = CompiledTemplate(Template("hostile", 1, tuple(TemplateRow(10, "main", 1, None, *row) for row in rows)))
    with pytest.raises(TemplateError, match="exceeded 0.01 s"):   # the path takes far longer than that
        template.run({"moves": [Move("feed", 1.0, 2.0)]}, deadline_seconds=0.01)


@pytest.mark.parametrize("columns, words, seen", [case for case in HOSTILE if not case[2]],
                         ids=lambda value: str(value)[:50] if isinstance(value, tuple) else None)
def test_what_a_refused_row_built_stays_within_the_budget(columns, words, seen):
    message, peak = run_traced([columns], {"z2": 19})
    assert words in message
    assert peak < MAX_BYTES + (16 << 20)


def hundreds_of_large_integers(rows):
    """Rows of the budget escape (issue 13): each `s` assigns one integer of 4,001 bits to a few
    hundred names, cheap to compute and to hold (one object), 1,205 digits each as JSON."""
    assignments, k = ["a0 = 1 << 4000"], 1
    while len("; ".join([*assignments, f"a{k} = a0"])) < MAX_EXPRESSION_LENGTH:
        assignments.append(f"a{k} = a0")
        k += 1
    return "; ".join(assignments), rows


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_hundreds_of_large_integers_keep_a_bounded_trace_or_are_refused(fresh_database_url, tmp_path):
    """Either the program is stored with a trace within its bound (the integers summarised, the
    rows past the bound counted), or the compile runs out of time and is refused in one line."""
    s, rows = hundreds_of_large_integers(100)
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, s) "
                     "SELECT 'spur', 90000 + g, 'main', 1, %s FROM generate_series(1, %s) g", (s, rows))
        conn.commit()
        before = counts(conn)
    done = engine(fresh_database_url, "instantiate", "--gear", "42", "--draft")   # a draft: printed, no file
    with psycopg.connect(fresh_database_url) as conn:
        if done.returncode == 1:
            assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: class spur row 900"), done.stderr
            assert "compiling the template exceeded" in done.stderr
            assert counts(conn) == before
            return
        assert done.returncode == 0, done.stderr
        trace, size = conn.execute("SELECT trace, octet_length(trace::text) "
                                   "FROM program ORDER BY id DESC LIMIT 1").fetchone()
    assert size <= MAX_TRACE_BYTES + 64 * 1024   # the row entries, and the job's inputs once
    assert trace["omitted"]["rows"] > 0 and trace["omitted"]["from_row"] > 90001
    kept = [entry for entry in trace["rows"] if entry["row"] > 90000]
    assert kept and kept[0]["computed"]["a7"] == f"<integer of {(1 << 4000).bit_length()} bits>"


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_lint_of_hundreds_of_large_integers_finishes(fresh_database_url):
    """Every name the rows read they assign first: lint passes them, or names the row at which
    the compile ran out of time, and goes on to the next class."""
    s, rows = hundreds_of_large_integers(100)
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, s) "
                     "SELECT 'spur', 90000 + g, 'main', 1, %s FROM generate_series(1, %s) g", (s, rows))
        conn.commit()
    linted = engine(fresh_database_url, "lint")
    assert linted.returncode in (0, 1), linted.stderr
    problems = linted.stdout.splitlines() if linted.returncode else []
    assert all(" row 900" in line and "compiling the template exceeded" in line for line in problems), problems


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_trace_keeps_its_bound_and_counts_the_rows_past_it():
    """400 rows of 20 texts of 150 characters each: about 2.6 MB as JSON, more than a trace keeps."""
    statements = "; ".join(["a = 'x' * 150", *(f"b{k} = a" for k in range(19))])
    rows = tuple(TemplateRow(10 * k + 10, "main", 1, None, statements, None, None) for k in range(400))
    trace = CompiledTemplate(Template("many", 1, rows)).run({}).trace
    kept = sum(len(json.dumps(entry)) for entry in trace["rows"])
    assert kept <= MAX_TRACE_BYTES < kept + len(json.dumps(rows[0].s)) * 400
    assert trace["rows"][0]["computed"]["b3"] == "x" * 150
    assert trace["omitted"] == {"from_row": trace["rows"][-1]["row"] + 10, "rows": 400 - len(trace["rows"])}


def test_the_trace_keeps_integers_up_to_64_bits_and_summarises_longer_ones():
    rows = (TemplateRow(10, "main", 1, None, "small = (1 << 64) - 1; large = 1 << 64; truth = z2 > 0", "'x'", None),)
    computed = CompiledTemplate(Template("ints", 1, rows)).run({"z2": 1}).trace["rows"][0]["computed"]
    assert computed == {"small": 2 ** 64 - 1, "large": "<integer of 65 bits>", "truth": True}


def test_rows_sharing_a_text_are_each_checked_with_all_their_columns():
    """A body is compiled once however many rows hold it (issue 27: a long program repeats its
    lines): a row whose `o` an earlier row had is still refused for its own p_emit, and each row
    holding a refused text is named, not only the first."""
    rows = [TemplateRow(10, "main", 1, None, None, '"G0 X1."', None),
            TemplateRow(20, "main", 1, None, None, '"G0 X1."', "__import__('os')"),
            TemplateRow(30, "main", 1, None, None, "open('x')", None),
            TemplateRow(40, "main", 1, None, None, "open('x')", None),
            TemplateRow(50, "main", 1, None, None, '"G0 X1."', None)]
    with rows_compiled_once():
        problems = structural_problems("spur", rows)
        compiled = [compile_row("spur", row) for row in (rows[0], rows[4])]
    assert [(problem.row_id, problem.column) for problem in problems] == [(20, "p_emit"), (30, "o"), (40, "o")]
    assert [row.row.id for row in compiled] == [10, 50]
