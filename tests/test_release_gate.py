"""The release gate (issue 15): a class's draft reaches the shop floor only through `engine
template release`, which refuses a draft with a broken expression, a failing golden test or a
static-analysis finding (naming the row, the column, the test), shows what the release changes in
the stored programs, records the release, and is only for engine_releaser."""
import json

import psycopg
import pytest
from helpers.roles import as_role
from psycopg import sql

from engine.errors import EngineError
from engine.nc.lineage import without_lineage
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.release.gate import release
from engine.release.golden import run_golden_tests
from engine.release.impact import impact
from engine.templates.analysis import analyse, class_findings
from engine.templates.rows import Template, TemplateRow
from engine.templates.store import load_template
from engine.templates.versions import released_template, released_version

SEEDED_CLASSES = ("spur", "helical", "duplex", "taper", "crowned", "worm_wheel", "turning_iso", "turning_840d")
COOLANT_ROW = 1800   # seed_templates/classes/spur.csv: cutcond 1, `"M8"` when coolant
COOLANT_OFF_ROW = 2900   # cutcond 2, `"M9"` when coolant: no seeded golden test reads it
COMMENTED = '"M9 ; COOLANT OFF"'


EDIT = sql.SQL("UPDATE template_view SET {} = %s WHERE gear_class = %s AND id = %s")


def edit(conn, gear_class, row_id, **columns):
    """One row of the class's draft changed through template_view, as a DBA does."""
    for column, value in columns.items():
        updated = conn.execute(EDIT.format(sql.Identifier(column)), (value, gear_class, row_id)).rowcount
        assert updated == 1


def refusal(conn, gear_class, **options) -> EngineError:
    with pytest.raises(EngineError) as refused:
        release(conn, gear_class, **options)
    return refused.value


def stored_lines(conn, program_id):
    lines, row_ids = conn.execute("SELECT lines, row_ids FROM program WHERE id = %s", (program_id,)).fetchone()
    return without_lineage(lines, row_ids)


# --- the gate refuses ------------------------------------------------------------------------------

def test_a_broken_expression_cannot_be_released_and_the_refusal_names_row_and_column(conn):
    """The issue's edit: the inner quotes forgotten. UPDATE 1, but the release is refused."""
    before = released_version(conn, "spur")
    edit(conn, "spur", COOLANT_ROW, o="M8 ; COOLANT ON")
    error = refusal(conn, "spur", dry_run=True)
    assert f"row {COOLANT_ROW} column o" in str(error)
    assert any(f"row {COOLANT_ROW} column o" in problem for problem in error.problems)
    error = refusal(conn, "spur")
    assert f"row {COOLANT_ROW} column o" in str(error)
    assert released_version(conn, "spur") == before


def test_a_draft_failing_a_golden_test_cannot_be_released_and_the_refusal_names_the_test(conn):
    conn.execute("INSERT INTO template_test (gear_class, name, gear_id, expect) "
                 "VALUES ('spur', 'coolant_on_before_cutting', 42, ARRAY['line: M8'])")
    assert all(result.passed for result in run_golden_tests(conn, ["spur"], draft=False))
    edit(conn, "spur", COOLANT_ROW, o='"M9"')
    error = refusal(conn, "spur")
    assert any("spur/coolant_on_before_cutting" in problem for problem in error.problems)
    assert "golden test" in str(error)
    assert released_version(conn, "spur") == released_template(conn, "spur").version


def test_a_golden_test_of_a_descendant_is_run_against_its_draft_too(conn):
    """duplex inherits spur's coolant row: a spur edit that breaks a duplex test is refused."""
    conn.execute("INSERT INTO template_test (gear_class, name, gear_id, expect) "
                 "VALUES ('duplex', 'duplex_coolant_on', 54, ARRAY['line: M8'])")
    edit(conn, "spur", COOLANT_ROW, o='"M9"')
    assert any("duplex/duplex_coolant_on" in problem for problem in refusal(conn, "spur").problems)


def test_a_static_analysis_finding_refuses_the_release_naming_the_row(conn):
    conn.execute("INSERT INTO template_view (gear_class, id, t, n, o, p_emit) "
                 "SELECT gear_class, 805, t, n, o, p_emit FROM template_view WHERE gear_class = 'spur' AND id = 800")
    error = refusal(conn, "spur", dry_run=True)
    assert "row 805 column o" in str(error) and "repeats row 800" in str(error)


def test_a_class_without_a_draft_is_one_line(conn):
    error = refusal(conn, "helical", dry_run=True)
    assert "no draft" in str(error) and "\n" not in str(error)


# --- static analysis ------------------------------------------------------------------------------

def row(row_id, o=None, p_calc=None, s=None, p_emit=None, t="main", n=1):
    return TemplateRow(row_id, t, n, p_calc, s, o, p_emit)


def findings(rows, names=("z2", "coolant")):
    return [(f.rule, f.row_id, f.column) for f in analyse(Template("probe", 1, tuple(rows)),
                                                          lambda t, n: frozenset(names))]


@pytest.mark.parametrize("condition", ["False", "1 > 2", "0", "1 = 2", "NOT TRUE"])
def test_a_condition_false_for_every_job_is_found(condition):
    assert findings([row(10, '"M8"', p_emit=condition)]) == [("constant-false", 10, "p_emit")]
    assert findings([row(10, '"M8"', p_calc=condition, s="a = 1")]) == [("constant-false", 10, "p_calc")]


@pytest.mark.parametrize("condition", ["True", "1 < 2", "coolant", "z2 > 0 or False"])
def test_a_condition_that_may_hold_is_not_a_finding(condition):
    assert findings([row(10, '"M8"', p_emit=condition)]) == []


def test_an_intermediate_written_twice_without_a_read_between_is_a_dead_write():
    rows = [row(10, s="depth = z2 * 2"), row(20, '"G90"'), row(30, s="depth = z2 * 3"), row(40, 'f"X{depth}"')]
    assert findings(rows) == [("dead-write", 10, "s")]


@pytest.mark.parametrize("between", [
    row(20, 'f"; {depth}"'),                       # read between the writes
    row(20, '"G90"', p_emit="depth > 1"),          # read by a condition
])
def test_a_write_read_before_the_next_one_is_live(between):
    rows = [row(10, s="depth = z2 * 2"), between, row(30, s="depth = z2 * 3"), row(40, 'f"X{depth}"')]
    assert findings(rows) == []


def test_a_conditional_second_write_or_one_reading_the_name_keeps_the_first():
    conditional = [row(10, s="depth = z2"), row(30, p_calc="coolant", s="depth = z2 * 3"), row(40, 'f"X{depth}"')]
    reading = [row(10, s="depth = z2"), row(30, s="depth = depth * 3"), row(40, 'f"X{depth}"')]
    assert findings(conditional) == [] and findings(reading) == []


def test_a_row_right_after_its_twin_is_a_pasted_duplicate():
    rows = [row(10, '"G90"'), row(20, '"G90"'), row(30, '"G90"'), row(40, '"G90"', p_emit="coolant")]
    found = analyse(Template("probe", 1, tuple(rows)), lambda t, n: frozenset({"coolant"}))
    assert [(f.rule, f.row_id, f.column) for f in found] == [("duplicate-row", 20, "o"), ("duplicate-row", 30, "o")]
    assert "repeats row 10" in found[0].message and "repeats row 20" in found[1].message   # each its own twin
    assert all("pasted" in f.message for f in found)


def test_a_plain_line_repeated_further_on_or_a_second_blank_line_is_the_programs_content():
    """Real programs repeat a retract or a tool call, and blank lines come in pairs (tests/data/nc)."""
    assert findings([row(10, '"G90"'), row(20, '"G91"'), row(30, '"G90"'), row(40, 'f"X{z2}"'),
                     row(50, '"G91"'), row(60, 'f"X{z2}"')]) == []
    assert findings([row(10, '"G90"'), row(20, '""'), row(30, '""'), row(40, '"G91"')]) == []


def test_the_same_line_in_another_module_is_not_a_paste():
    assert findings([row(10, '"G90"'), row(20, '"G90"', t="cutcond"), row(30, '"G90"', n=2)]) == []


@pytest.mark.parametrize("computing", [
    {"o": '"M8"', "p_emit": "coolant"},
    {"p_calc": "coolant", "s": "half = z2 / 2"},
    {"s": "half = z2 / 2"},
], ids=["p_emit", "p_calc", "s"])
def test_a_repeated_row_that_computes_is_found_wherever_it_is(computing):
    rows = [row(10, **computing), row(20, 'f"; {z2}"'), row(30, 'f"; {half}"' if "s" in computing else '"G90"'),
            row(40, **computing), row(50, 'f"; {half}"' if "s" in computing else '"G91"')]
    found = analyse(Template("probe", 1, tuple(rows)), lambda t, n: frozenset({"z2", "coolant"}))
    assert [(f.rule, f.row_id, f.column) for f in found] == [("duplicate-row", 40, "o")]
    assert "repeats row 10" in found[0].message and "dead" in found[0].message


def test_a_name_read_before_any_row_or_parameter_gives_it_is_found():
    rows = [row(10, 'f"X{depth:.3f}"'), row(20, s="depth = z2 * 2"), row(30, 'f"Y{width}"')]
    found = analyse(Template("probe", 1, tuple(rows)), lambda t, n: frozenset({"z2"}))
    assert [(f.rule, f.row_id, f.column) for f in found] == [("read-before-given", 10, "o"),
                                                             ("read-before-given", 30, "o")]
    assert "before row 20 assigns it" in found[0].message and "no parameter" in found[1].message


def test_names_given_by_earlier_rows_parameters_or_the_same_row_are_not_findings():
    rows = [row(10, s="depth = z2 * 2; half = depth / 2"), row(20, 'f"X{half} {depth}"')]
    assert findings(rows) == []


@pytest.mark.parametrize("gear_class", SEEDED_CLASSES)
def test_the_seeded_templates_have_no_finding(conn, gear_class):
    assert class_findings(conn, gear_class, load_template(conn, gear_class)) == []


# --- impact ---------------------------------------------------------------------------------------

def test_impact_counts_the_stored_programs_whose_lines_the_draft_changes(conn):
    """Programs of spur (and its descendant duplex) and of helical (not below spur) stored from the
    released templates; then spur's coolant-on line is printed only for gears of 30 teeth or more.
    Which programs change follows from the gears' own teeth and coolant; and an editor's --draft
    programs, diffed here, agree."""
    gears = [42, 45, 46, 54, 43]
    released = {gear: instantiate_gear(conn, gear) for gear in gears}
    edit(conn, "spur", COOLANT_ROW, p_emit="coolant AND z2 >= 30")
    teeth = dict(conn.execute("SELECT id, teeth FROM gear WHERE id = ANY(%s)", (gears,)).fetchall())
    below_spur = [gear for gear in gears if released[gear].gear_class in ("spur", "duplex")]
    coolant = {gear: conn.execute("SELECT (params ->> 'coolant')::boolean FROM job WHERE id = %s",
                                  (released[gear].job_id,)).fetchone()[0] for gear in gears}
    expected = {released[gear].job_id for gear in below_spur if coolant[gear] and teeth[gear] < 30}

    report = impact(conn, "spur")

    assert report.jobs == len(below_spur) and report.failures == []
    assert report.changed == len(expected) > 0 and {diff.job_id for diff in report.diffs} == expected
    assert all("-M8" in diff.diff for diff in report.diffs)
    drafted = {gear: instantiate_gear(conn, gear, mode=RunMode(draft=True)) for gear in below_spur}
    differing = {released[gear].job_id for gear in below_spur
                 if _without_version(conn, released[gear]) != _without_version(conn, drafted[gear])}
    assert differing == expected


def _without_version(conn, program):
    """The lines without the `; TEMPLATE class vN` line (a draft has another version number)."""
    return [line for line in stored_lines(conn, program.program_id) if not line.startswith("; TEMPLATE")]


def test_impact_of_a_class_without_changes_is_zero(conn):
    instantiate_gear(conn, 43)
    report = impact(conn, "helical")
    assert (report.jobs, report.changed, report.diffs) == (1, 0, [])


def test_impact_names_the_jobs_the_draft_fails_for(conn):
    job = instantiate_gear(conn, 42).job_id
    edit(conn, "spur", COOLANT_ROW, o='f"M8 {coolant_code}"')
    report = impact(conn, "spur")
    assert [failure.job_id for failure in report.failures] == [job]
    assert "coolant_code" in report.failures[0].error


# --- release, runners, roles ----------------------------------------------------------------------

def test_after_release_runners_get_the_new_version(conn):
    edit(conn, "spur", COOLANT_OFF_ROW, o=COMMENTED)
    draft_version = load_template(conn, "spur").version
    with as_role(conn, "engine_runner"):
        before = instantiate_gear(conn, 45)
    assert "M9 ; COOLANT OFF" not in before.lines
    report = release(conn, "spur")
    assert report.release_id is not None and released_version(conn, "spur") == draft_version
    with as_role(conn, "engine_runner"):
        after = instantiate_gear(conn, 45)
    assert after.template_version == draft_version and "M9 ; COOLANT OFF" in after.lines
    assert report.drafts_below == ["duplex"]   # spur's change gave duplex a draft of its own
    assert released_version(conn, "duplex") < load_template(conn, "duplex").version
    with as_role(conn, "engine_runner"):
        duplex = instantiate_gear(conn, 54)   # duplex's runners keep its released rows
    assert "M9" in duplex.lines and "M9 ; COOLANT OFF" not in duplex.lines


def test_the_release_records_tests_and_impact(conn):
    conn.execute("INSERT INTO template_test (gear_class, name, gear_id, expect) "
                 "VALUES ('spur', 'coolant_comment', 42, ARRAY['match: ^M9'])")
    instantiate_gear(conn, 42)
    edit(conn, "spur", COOLANT_OFF_ROW, o=COMMENTED)
    release(conn, "spur")
    tests, recorded = conn.execute("SELECT tests, impact FROM template_release WHERE gear_class = 'spur' "
                                   "ORDER BY id DESC LIMIT 1").fetchone()
    assert {"class": "spur", "name": "coolant_comment", "passed": True} in tests
    assert (recorded["jobs"], recorded["changed"]) == (1, 1)


@pytest.mark.parametrize("role", ["engine_runner", "engine_editor"])
def test_a_runner_or_an_editor_cannot_release(conn, role):
    edit(conn, "spur", COOLANT_OFF_ROW, o=COMMENTED)
    before = released_version(conn, "spur")
    with as_role(conn, role):
        error = refusal(conn, "spur")
    assert "engine_releaser" in str(error) and role in str(error)
    assert released_version(conn, "spur") == before


def test_a_releaser_releases(conn):
    edit(conn, "spur", COOLANT_OFF_ROW, o=COMMENTED)
    with as_role(conn, "engine_releaser"):
        report = release(conn, "spur")
        assert report.release_id is not None
    assert conn.execute("SELECT role FROM template_release WHERE id = %s",
                        (report.release_id,)).fetchone()[0] == "engine_releaser"


# --- the command line ------------------------------------------------------------------------------

def committed_edit(url, row_id=COOLANT_ROW, **columns):
    with psycopg.connect(url) as conn:
        edit(conn, "spur", row_id, **columns)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_release_on_the_command_line_and_history(run):
    assert run("instantiate", "--gear", 42).exit_code == 0
    committed_edit(run.url, o="M8 ; COOLANT ON")
    refused = run("template", "release", "--class", "spur", "--yes")
    assert refused.exit_code == 1 and f"row {COOLANT_ROW} column o" in refused.stderr
    committed_edit(run.url, o='"M8"')
    committed_edit(run.url, COOLANT_OFF_ROW, o=COMMENTED)
    dry = run("template", "release", "--class", "spur", "--dry-run", "--json")
    payload = json.loads(dry.stdout)
    assert dry.stdout.count("\n") == 1 and not payload["released"]
    assert payload["impact"]["changed"] == payload["impact"]["proved"] == 1
    assert "+M9 ; COOLANT OFF" in payload["impact"]["diffs"][0]["diff"]
    declined = CliInput(run, "n\n")("template", "release", "--class", "spur")
    assert "1 program(s) change" in declined.stdout and "nothing released" in declined.stdout
    released = run("template", "release", "--class", "spur", "--yes")
    assert released.exit_code == 0 and "released class spur" in released.stdout
    committed_edit(run.url, COOLANT_OFF_ROW, o='"M9 ; COOLANT OFF, FLOOD"')
    history = run("template", "history", "--class", "spur").stdout
    states = [line.split()[1] for line in history.splitlines() if line.startswith("v")]
    assert states == ["retired", "superseded", "superseded", "released", "draft"]   # v2 broken, v3 mended
    assert "1 of 1 stored job(s) changed" in history


class CliInput:
    """The CLI with text typed at its prompts."""

    def __init__(self, run, text):
        self.run, self.text = run, text

    def __call__(self, *args):
        from click.testing import CliRunner

        from engine.cli.app import main

        return CliRunner().invoke(main, ["--database-url", self.run.url, *args], input=self.text)


def test_release_help_shows_an_example(read_only_run):
    assert "engine template release --class spur --dry-run" in read_only_run("template", "release", "--help").stdout


def test_a_draft_that_drives_a_stored_hobbing_job_beyond_the_machine_is_refused(conn):
    """Third adversary: a spur draft writing S at 5·n0 for 48-tooth gears only (no golden gear has
    48 teeth) passed the gate with '0 fail'; gear 46's stored job would run its hob at 5·323 r/min
    on a 1000 r/min spindle. The impact reads each draft program with the machine's verifier."""
    job_id = instantiate_gear(conn, 46).job_id
    n0 = conn.execute("SELECT (params ->> 'n0')::float FROM job WHERE id = %s", (job_id,)).fetchone()[0]
    spindle_max = conn.execute("SELECT spindle_max FROM machine WHERE name = 'hobber-840d'").fetchone()[0]
    assert 5 * n0 > spindle_max >= n0
    edit(conn, "spur", 1700, o='f"M3 S{n0 * 5 if z2 == 48 else n0}"')
    problems = refusal(conn, "spur", dry_run=True).problems
    assert any(f"stored job {job_id} " in problem and "exceeds" in problem for problem in problems), problems


@pytest.mark.parametrize("workers", [1, 2])
def test_a_draft_whose_program_the_hobbing_simulation_refuses_for_a_stored_job_is_refused(conn, workers):
    """Issue 28: impact proves every program it changes. A spur draft that makes the axial cut a
    rapid for 48-tooth gears only (no golden gear has 48 teeth, and the move is inside the travel, so
    the verifier reads it) would drive gear 46's stored job through its blank at rapid. The impact
    follows each changed program with the hobbing simulation against the job's gear and hob, in one
    process or forked workers alike."""
    job_id = instantiate_gear(conn, 46).job_id
    other = instantiate_gear(conn, 42).job_id
    teeth = dict(conn.execute("SELECT id, teeth FROM gear WHERE id IN (42, 46)").fetchall())
    assert teeth[46] == 48 != teeth[42]
    edit(conn, "spur", 2700, o='f"G{0 if z2 == 48 else 1} Z{z_to:.3f} F{feed_axial:.1f}"')   # the last cut
    report = impact(conn, "spur", workers)
    assert [failure.job_id for failure in report.failures] == [job_id] and report.failures[0].released_makes
    assert "gear 46" in report.failures[0].error and other not in {diff.job_id for diff in report.diffs}
    assert report.proved == 1   # gear 42's program is unchanged: not proved again
    problems = refusal(conn, "spur", dry_run=True, workers=workers).problems
    assert any(f"stored job {job_id} " in problem and "gear 46" in problem for problem in problems), problems


def test_the_impact_proved_in_two_workers_is_the_impact_proved_here(conn):
    """The changed programs of several stored jobs proved in forked workers: the same changes, the
    same failures with the same reasons, in job order; the connection the workers inherit is not
    theirs to use, and it still works after them."""
    for gear in (42, 45, 46, 54):
        instantiate_gear(conn, gear)
    edit(conn, "spur", COOLANT_ROW, p_emit="coolant AND z2 >= 30")
    edit(conn, "spur", 2700, o='f"G{0 if z2 == 48 else 1} Z{z_to:.3f} F{feed_axial:.1f}"')
    here, two = impact(conn, "spur"), impact(conn, "spur", workers=2)
    assert here == two and len(here.failures) == 1 and here.changed >= 2
    assert conn.execute("SELECT count(*) FROM job").fetchone()[0] >= 4


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_draft_that_sends_a_stored_lathe_class_job_through_its_blank_is_refused(run, tmp_path):
    """New-user review of issue 28: a class job (instantiate --class --params, a shop's own lathe
    program imported) was made again by the impact as if it were a drawing's turning job, failed
    for want of a tool-change position with both versions, was listed as an older problem, and the
    draft that rapids into the part was released. The impact makes a class job from its rows alone
    and proves it against its stated blank, as engine.programs.remake does."""
    from helpers.class_jobs import import_emco, ok
    from helpers.releases import release_draft

    _, lines = import_emco(run, tmp_path)
    with psycopg.connect(run.url) as conn:
        release_draft(conn, "emco_neg")
    params = tmp_path / "blank.json"
    params.write_text(json.dumps({"stock_diameter": 26, "stock_z_front": 0, "stock_z_back": -40}))
    job_id = json.loads(ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--params", params,
                               "--json")).stdout)["job_id"]
    approach = lines.index("G00 X124.000 Z2.000")
    with psycopg.connect(run.url) as conn:
        row = conn.execute("SELECT id FROM template_view WHERE gear_class = 'emco_neg' ORDER BY id OFFSET %s LIMIT 1",
                           (approach,)).fetchone()[0]
        edit(conn, "emco_neg", row, o='"G00 X0.000 Z-15.000"')
        conn.commit()
        report = impact(conn, "emco_neg")
        assert [(failure.job_id, failure.released_makes) for failure in report.failures] == [(job_id, True)]
        assert "rapid through material" in report.failures[0].error, report.failures[0].error
    refusal = run("template", "release", "--class", "emco_neg", "--dry-run", "--without-golden-tests")
    assert refusal.exit_code == 1 and f"stored job {job_id} " in refusal.stderr, refusal.output
