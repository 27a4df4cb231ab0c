"""Every program explains itself (issue 12): its trace says for every row of its template
version whether it ran and emitted, and the values that decided it; checked here on every
seeded class against the stored program, the stored job and the template rows, with the
conditions evaluated again by plain Python from the recorded values."""
import math
import re

import psycopg
import pytest
from helpers.drawings import seed_drawing
from msgspec.structs import replace

from engine.hobbing.choices import Choices
from engine.nc.lineage import LINEAGE_ROW_ID
from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.remake import instantiate_job
from engine.templates.store import load_template
from importers.dxf import import_dxf

SEEDED_GEARS = {42: "spur", 43: "helical", 45: "spur", 50: "taper", 51: "crowned", 53: "worm_wheel", 54: "duplex"}
CHOICES = (Choices(), Choices(cuts=2, coolant=False, tailstock=False, feed_mode="conventional-climb"),
           Choices(shift_per_part=0.5), Choices(worm_feed="tangential"))
SQL_WORDS = ((r"\bAND\b", " and "), (r"\bOR\b", " or "), (r"\bNOT\b", " not "), (r"<>", "!="),
             (r"(?<![<>!=])=(?!=)", "=="))
FUNCTIONS = {name: getattr(math, name) for name in ("sqrt", "sin", "cos", "tan", "radians", "degrees", "ceil",
                                                    "floor", "fabs", "atan", "atan2", "hypot")}
FUNCTIONS.update({"abs": abs, "min": min, "max": max, "round": round, "int": int, "float": float, "len": len})


def stored(conn, program_id):
    return conn.execute("""SELECT p.lines, p.row_ids, p.trace, p.gear_class, j.params, j.module_params
                           FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s""", (program_id,)).fetchone()


def python_of(condition: str) -> str:
    """The seeded SQL-style conditions (AND, OR, NOT, =, <>) as Python, for the check only."""
    if not re.search(r"\b(AND|OR|NOT)\b|<>|(?<![<>!=])=(?!=)", condition):
        return condition
    for pattern, python in SQL_WORDS:
        condition = re.sub(pattern, python, condition)
    return condition


def check_trace(conn, program_id):
    lines, row_ids, trace, gear_class, params, module_params = stored(conn, program_id)
    template = {row.id: row for row in load_template(conn, gear_class).rows}
    rows, inputs = trace["rows"], trace["inputs"]
    assert [entry["row"] for entry in rows] == sorted(template)           # every row, in id order
    emitting = {entry["row"] for entry in rows if entry.get("emit")}
    assert row_ids.count(LINEAGE_ROW_ID) == 1                              # the engine's lineage line, no row's
    template_rows = set(row_ids) - {LINEAGE_ROW_ID}
    assert template_rows <= emitting                                       # every other line from an emitting row
    assert {row for row in emitting if "nc_path" not in template[row].o} <= template_rows
    read_from_outside = {(origin, name) for entry in rows for reads in entry.get("read", {}).values()
                         for name, origin in reads.items() if not origin.startswith("row ")}
    assert {(origin, name) for origin, names in inputs.items() for name in names} == read_from_outside
    computed = {}
    for entry in rows:
        row = template[entry["row"]]
        check_origins(entry, inputs, params, module_params, computed)
        check_decision(entry, row, values_read(entry, inputs, computed))
        computed.update((name, (entry["row"], value)) for name, value in entry.get("computed", {}).items())


def values_read(entry, inputs, computed) -> dict:
    """column -> {name: value}: from the program's inputs, or the value the named row computed."""
    def value(name, origin):
        if origin.startswith("row "):
            return entry["computed"][name] if origin == f"row {entry['row']}" else computed[name][1]
        return inputs[origin][name]
    return {column: {name: value(name, origin) for name, origin in reads.items()}
            for column, reads in entry.get("read", {}).items()}


def check_origins(entry, inputs, params, module_params, computed):
    """Each value read is the job's, its module's, or the value a named row computed."""
    for reads in entry.get("read", {}).values():
        for name, origin in reads.items():
            value = None if origin.startswith("row ") else inputs[origin][name]
            if origin == "job":
                assert value == json_scalar(params[name]), (entry["row"], name)
            elif origin.startswith("module "):   # a turning model adds the passes it computes to the stored ones
                stored_module = module_params.get(origin.split()[1], {})
                assert name not in stored_module or value == json_scalar(stored_module[name]), (entry["row"], name)
            elif origin.startswith("row "):
                source = int(origin.split()[1])
                own = source == entry["row"] and name in entry.get("computed", {})
                assert own or computed[name][0] == source, (entry["row"], name, origin)   # the latest to compute it
            else:
                assert origin == "template" and name == "template_version"


def json_scalar(value):
    return value if isinstance(value, (bool, int, float, str, type(None))) else pytest.approx(value)


def check_decision(entry, row, values):
    """A row that did not emit names the condition that decided it, with values that decide it
    the same way when Python evaluates the condition again."""
    if row.s is not None and row.p_calc is not None:
        assert entry["calc"] is decided(row.p_calc, values["p_calc"])
        if not entry["calc"]:
            assert "emit" not in entry and "computed" not in entry
            return
    if row.o is None:
        assert "emit" not in entry
        return
    expected = True if row.p_emit is None else decided(row.p_emit, values["p_emit"])
    assert entry["emit"] is expected, (entry["row"], row.p_emit, entry)


def decided(condition: str, values: dict) -> bool:
    return bool(eval(python_of(condition), {"__builtins__": {}, **FUNCTIONS}, dict(values)))


@pytest.mark.parametrize("gear_id", sorted(SEEDED_GEARS))
@pytest.mark.parametrize("choices", CHOICES, ids=["default", "two-cuts-dry", "shift-per-part", "tangential"])
def test_every_seeded_hobbing_class_s_trace_explains_each_row(conn, gear_id, choices):
    if conn.execute("SELECT gear_class FROM gear WHERE id = %s", (gear_id,)).fetchone()[0] == "worm_wheel":
        choices = replace(choices, feed_mode=None)   # no axial pass: a feed mode given is refused
    program = instantiate_gear(conn, gear_id, choices=choices)
    check_trace(conn, program.program_id)


@pytest.mark.parametrize("machine", ["lathe-iso", "lathe-840d"])
def test_turning_classes_trace_explains_each_row(conn, tmp_path, machine):
    seed_drawing(tmp_path / "part.dxf")
    job = import_dxf(conn, tmp_path / "part.dxf", machine).job_id
    check_trace(conn, instantiate_job(conn, job).program_id)


def test_a_trace_is_stored_with_single_batch_and_remade_programs(conn):
    single = instantiate_gear(conn, 42)
    batch = instantiate_gears(conn, 42, 47)
    remade = instantiate_job(conn, single.job_id)
    ids = [single.program_id, remade.program_id,
           *range(batch.first_program_id, batch.last_program_id + 1)]
    traces = conn.execute("SELECT id, jsonb_array_length(trace->'rows') FROM program WHERE id = ANY(%s)",
                          (ids,)).fetchall()
    assert len(traces) >= 2 + batch.programs and all(length and length > 10 for _, length in traces)
    for program_id, _ in traces:
        check_trace(conn, program_id)


def test_the_program_trace_view_has_a_row_per_template_row_with_its_lines(conn):
    program = instantiate_gear(conn, 42, choices=Choices(coolant=False))
    rows = conn.execute("SELECT row_id, emit, p_emit, read, lines FROM program_trace WHERE program_id = %s "
                        "ORDER BY position", (program.program_id,)).fetchall()
    assert [row[0] for row in rows] == [row.id for row in load_template(conn, "spur").rows]
    by_row = {row[0]: row for row in rows}
    assert by_row[1800][1:4] == (False, False, {"p_emit": {"coolant": "job"}, "o": {}})
    assert by_row[1700][4] == ["M3 S246"] and by_row[1700][1] is True
    inputs = dict(((origin, name), value) for origin, name, value in conn.execute(
        "SELECT origin, name, value FROM program_input WHERE program_id = %s", (program.program_id,)))
    assert inputs[("job", "coolant")] is False and inputs[("job", "z2")] == 19


def test_engine_explain_says_why_a_line_is_missing(run):
    made = run("instantiate", "--gear", "42", "--no-coolant", "--json")
    program_id = __import__("json").loads(made.stdout)["program_id"]
    explained = run("explain", "--program", program_id, "--row", "1800")
    assert explained.exit_code == 0
    assert explained.stdout == "1800 not emitted: p_emit coolant = False (job)\n"
    whole = run("explain", "--program", program_id).stdout.splitlines()
    assert 'EGON(C,"FINE",B,-1,19) emitted' in whole[next(i for i, line in enumerate(whole)
                                                          if line.startswith("1500 "))]
    assert "z2 = 19 (job)" in next(line for line in whole if line.startswith("1500 "))


def test_instantiate_explain_prints_the_same_for_a_new_program(run):
    made = run("instantiate", "--gear", "42", "--no-coolant", "--explain")
    assert made.exit_code == 0 and made.stdout.startswith("%_N_GEAR42_MPF")
    assert "1800 not emitted: p_emit coolant = False (job)" in made.stderr.splitlines()


@pytest.mark.parametrize("args, words", [
    (("explain", "--program", "999999"), "program 999999 does not exist"),
    (("instantiate", "--gears", "42-43", "--explain"), "--explain explains one program"),
])
def test_explain_errors_are_one_line(read_only_run, args, words):
    refused = read_only_run(*args)
    assert refused.exit_code == 1 and words in refused.stderr and refused.stderr.count("\n") == 1


# A copy of a program under a new id, its lineage line naming that id (the database checks it).
COPY_WITHOUT_TRACE = """
INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace)
SELECT n.id, p.job_id, p.gear_class, p.template_version, p.template_hash, p.name,
       ARRAY(SELECT CASE WHEN l.row_id = -1 THEN regexp_replace(l.text, 'PROGRAM \\d+', 'PROGRAM ' || n.id)
                         ELSE l.text END
             FROM unnest(p.lines, p.row_ids) WITH ORDINALITY AS l (text, row_id, number) ORDER BY l.number),
       p.row_ids, NULL
FROM program p, (SELECT nextval('program_id_seq') AS id) n WHERE p.id = %s RETURNING id"""


def test_a_program_stored_without_a_trace_says_so_and_is_not_its_rendering(run):
    made = run("instantiate", "--gear", "42", "--json")
    program_id = __import__("json").loads(made.stdout)["program_id"]
    with psycopg.connect(run.url) as conn:   # programs are records: a copy stored without its trace
        program_id = conn.execute(COPY_WITHOUT_TRACE, (program_id,)).fetchone()[0]
    refused = run("explain", "--program", program_id)
    assert refused.exit_code == 1 and "MISMATCH" in refused.stderr and "no trace stored" in refused.stderr


def test_a_computed_text_with_a_nul_is_traced_not_fatal(conn):
    from engine.templates.decision_table import CompiledTemplate
    from engine.templates.rows import Template, TemplateRow

    rows = (TemplateRow(1, "main", 1, None, "marker = 'a' + chr0 + 'b'", None, None),
            TemplateRow(2, "main", 1, None, None, "'G90'", None))
    result = CompiledTemplate(Template("nul", 1, rows)).run({"chr0": "\x00"})
    stored = conn.execute("SELECT %s::jsonb", (__import__("json").dumps(result.trace),)).fetchone()[0]
    assert stored["rows"][0]["computed"]["marker"] == "a\\x00b" and result.lines == ["G90"]
