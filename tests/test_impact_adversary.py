"""Adversary of issue 28's impact proofs (engine.release.impact): drafts and stored jobs built to
slip a program past the release gate that would be wrong (or refused) at the machine."""
import pytest
from psycopg import sql

from engine.errors import EngineError
from engine.library.nc_import import import_nc
from engine.programs.class_jobs import instantiate_class
from engine.programs.instantiate import instantiate_gear
from engine.release.gate import release
from engine.release.impact import impact
from engine.release.version_lines import same_program

SPEED_ROW, LAST_CUT_ROW, COOLANT_ROW, COOLANT_OFF_ROW = 1700, 2700, 1800, 2900   # seed_templates/classes/spur.csv
# A shop's own ISO lathe program (tests/test_turning_class_jobs.py): one rough pass at Ø36 from Z2 to Z-40.
SHAFT = ["%", "O0001 (SHAFT)", "G21 G18 G40 G90", "G00 X124.000 Z50.000", "T0101", "G97 S600 M03", "G98 F150.000",
         "G00 X44.000 Z2.000", "G01 X36.000 Z2.000", "G01 X36.000 Z-40.000", "G00 X44.000 Z-40.000",
         "G00 X44.000 Z2.000", "G00 X124.000 Z50.000", "M05", "M30", "%"]
EDIT = sql.SQL("UPDATE template_view SET {} = %s WHERE gear_class = %s AND id = %s")


def edit(conn, gear_class, row_id, **columns):
    for column, value in columns.items():
        assert conn.execute(EDIT.format(sql.Identifier(column)), (value, gear_class, row_id)).rowcount == 1


def refused_problems(conn, gear_class, **options) -> list[str]:
    with pytest.raises(EngineError) as refused:
        release(conn, gear_class, dry_run=True, without_golden_tests=True, **options)
    return getattr(refused.value, "problems", [str(refused.value)])


def teeth(conn, gear_id) -> int:
    return conn.execute("SELECT teeth FROM gear WHERE id = %s", (gear_id,)).fetchone()[0]


# --- a line the machine's matcher reads as a second lineage --------------------------------------

@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_lineage_shaped_line_for_48_teeth_only_is_refused(conn):
    """Every program that is stored passes refuse_lineage_shaped (engine.programs.verified_run): a
    draft writing `; PROGRAM 1 TEMPLATE ...` for gear 46's 48 teeth only (no golden gear has 48)
    would, once released, make gear 46's stored job refused at every remake. The gate must refuse it."""
    job_id = instantiate_gear(conn, 46).job_id
    assert teeth(conn, 46) == 48
    # the word in a replacement field: the static check (row 2900 "reads as a lineage line") reads literals only
    edit(conn, "spur", COOLANT_OFF_ROW, o='f"; {\'PROGRAM\'} 1 TEMPLATE spur v1" if z2 == 48 else "M9"')
    problems = refused_problems(conn, "spur")
    assert any(f"stored job {job_id} " in problem and "lineage" in problem for problem in problems), problems


# --- forked workers -------------------------------------------------------------------------------

def _gear_without_diameters(conn, gear_id):
    """The gear record edited after its job was stored so that it can no longer be completed: two
    teeth, no diameters (root = m·(2 + 2) − 4.5·m < 0, engine.gears.records._completed refuses it)."""
    conn.execute("UPDATE gear SET teeth = 2, tip_diameter = NULL, root_diameter = NULL WHERE id = %s", (gear_id,))


@pytest.mark.parametrize("workers", [1, 2])
def test_a_gear_record_that_no_longer_loads_is_named_in_workers_as_in_one_process(conn, workers):
    """read_records swallows load_gear's EngineError ('the proof names it'); the proof then calls
    load_gear again, which in a forked worker has no connection."""
    jobs = [instantiate_gear(conn, gear).job_id for gear in (42, 45, 46)]
    _gear_without_diameters(conn, 46)
    edit(conn, "spur", COOLANT_OFF_ROW, o='"M9 ; COOLANT OFF"')   # changes every spur program
    report = impact(conn, "spur", workers)
    assert [failure.job_id for failure in report.failures] == [jobs[2]]
    assert "gear 46" in report.failures[0].error and report.changed == 2


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_two_workers_report_what_one_process_reports(conn):
    """The workers make both programs of each job input, compare them and prove the changed ones
    (issue 28): the same diffs, failures (and whether the released version passes), counts and
    proofs as one process, in job order; a job with the same inputs as another is named too."""
    jobs = [instantiate_gear(conn, gear).job_id for gear in (42, 45, 46)]
    twin = conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params) "
                        "SELECT gear_id, gear_class, machine, hob_id, params, module_params FROM job WHERE id = %s "
                        "RETURNING id", (jobs[0],)).fetchone()[0]
    assert teeth(conn, 46) == 48 and {teeth(conn, 42), teeth(conn, 45)}.isdisjoint({48})
    edit(conn, "spur", SPEED_ROW, o='f"M3 S{n0 * 5 if z2 == 48 else n0}"')   # gear 46's hob beyond the spindle
    edit(conn, "spur", COOLANT_OFF_ROW, o='"M9 ; COOLANT OFF"')              # every spur program changes
    one, two = impact(conn, "spur", 1), impact(conn, "spur", 2)
    assert two == one
    assert [diff.job_id for diff in one.diffs] == [jobs[0], jobs[1], twin] and one.changed == 3
    assert [(failure.job_id, failure.released_makes) for failure in one.failures] == [(jobs[2], True)]
    assert one.jobs == 4 and one.proved == 3   # three distinct inputs changed, each proved once


# --- deduplicated inputs, descendants -------------------------------------------------------------

def test_two_stored_jobs_with_the_same_inputs_are_both_named(conn):
    """Jobs with identical parameters, gear and hob are evaluated once: the failure must still name
    each stored job, not only the first."""
    first = instantiate_gear(conn, 46).job_id
    second = conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params) "
                          "SELECT gear_id, gear_class, machine, hob_id, params, module_params FROM job WHERE id = %s "
                          "RETURNING id", (first,)).fetchone()[0]
    edit(conn, "spur", SPEED_ROW, o='f"M3 S{n0 * 5 if z2 == 48 else n0}"')
    problems = refused_problems(conn, "spur")
    assert all(any(f"stored job {job} " in problem for problem in problems) for job in (first, second)), problems


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_spur_draft_that_breaks_only_a_duplex_job_is_refused(conn):
    """duplex (gear 54, 30 teeth) inherits spur's rows: a spur edit for 30 teeth only changes no spur
    job's program but drives the stored duplex job's hob beyond the spindle."""
    spur = instantiate_gear(conn, 46).job_id
    duplex = instantiate_gear(conn, 54).job_id
    assert teeth(conn, 54) == 30 != teeth(conn, 46)
    conn.execute("DELETE FROM template_test WHERE gear_class = 'duplex'")   # gear 54 is duplex's golden gear
    edit(conn, "spur", SPEED_ROW, o='f"M3 S{n0 * 5 if z2 == 30 else n0}"')
    problems = refused_problems(conn, "spur")
    assert any(f"stored job {duplex} (duplex)" in problem for problem in problems), problems
    assert not any(f"stored job {spur} " in problem for problem in problems)


# --- exceptions that are not EngineError ----------------------------------------------------------

@pytest.mark.parametrize("expression", ["1 / (z2 - 48)", "10.0 ** (z2 * 10)", "[1][z2 - 47]", "int(str(z2) + 'x')"],
                         ids=["zero-division", "overflow", "index", "value"])
def test_a_draft_that_raises_a_python_error_for_48_teeth_only_is_refused_not_crashed(conn, expression):
    """The draft's rows raise inside the expression evaluator for gear 46's job only: the gate must
    name the job (an EngineError), not crash the release with a traceback."""
    job_id = instantiate_gear(conn, 46).job_id
    edit(conn, "spur", COOLANT_ROW, o=f'"M8" if z2 != 48 else f"M8 ; {{{expression}}}"')
    problems = refused_problems(conn, "spur")
    assert any(f"stored job {job_id} " in problem for problem in problems), problems


# --- a class job on a lathe (a class without a model: import-nc, instantiate --class) --------------

def test_a_draft_rapid_through_the_blank_of_a_stored_lathe_class_job_is_refused(conn, tmp_path):
    """The class job's program is made with its rows alone (engine.programs.class_jobs.class_job) and
    proved against the blank it implies. A draft rapid from the approach point (Ø44, Z2) to X0 Z-15
    crosses the Ø36 Z-40…2 blank the cut implies: every remake of the job after the release is refused
    by the turning simulation, so the gate must refuse the draft."""
    path = tmp_path / "SHAFT.NC"
    path.write_text("\n".join(SHAFT) + "\n")
    import_nc(conn, path, "shaft", {"speed": 600, "feed": 150.0})
    release(conn, "shaft", without_golden_tests=True)
    job_id = instantiate_class(conn, "shaft", {}, machine="lathe-iso").program.job_id
    approach = conn.execute("SELECT id FROM template_view WHERE gear_class = 'shaft' AND o = %s",
                            ('"G00 X44.000 Z2.000"',)).fetchone()[0]
    conn.execute("INSERT INTO template_view (gear_class, id, t, n, o) SELECT gear_class, %s, t, n, %s "
                 "FROM template_view WHERE gear_class = 'shaft' AND id = %s",
                 (approach + 5, '"G00 X0.000 Z-15.000"', approach))
    problems = refused_problems(conn, "shaft")
    assert any(f"stored job {job_id} " in problem and "rapid through material" in problem
               for problem in problems), problems


# --- the draft's own version number ---------------------------------------------------------------

def test_a_draft_that_reads_its_own_version_number_is_proved_as_it_will_run(conn):
    """Rows may read template_version (turning_840d's `; TEMPLATE` line does). The impact evaluates the
    draft as if it had the released version number, so a row that misbehaves only from the draft's
    number on (and for 48 teeth only: no golden gear) shows no change; released, the draft runs
    with its own number and gear 46's stored job's hob turns at 5·n0."""
    job_id = instantiate_gear(conn, 46).job_id
    released = conn.execute("SELECT released_version('spur')").fetchone()[0]
    edit(conn, "spur", SPEED_ROW, o=f'f"M3 S{{n0 * 5 if z2 == 48 and template_version > {released} else n0}}"')
    problems = refused_problems(conn, "spur")
    assert any(f"stored job {job_id} " in problem and "exceeds" in problem for problem in problems), problems


@pytest.mark.parametrize(("old", "new", "same"), [
    ("; TEMPLATE spur v3", "; TEMPLATE spur v5", True),                 # the number alone: no change
    ("(TEMPLATE spur v3)", "(TEMPLATE spur v5)", True),
    ("(TEMPLATE spur v3) G00 X3.", "(TEMPLATE spur v5) G00 X5.", False),  # ISO runs the block after it
    ("; TEMPLATE spur v3", "; TEMPLATE spur v5 S1615", False),
    ("M3 S323 ; TEMPLATE v3", "M3 S1615 ; TEMPLATE v5", False),
])
def test_only_a_template_comment_differing_in_its_version_number_is_no_change(old, new, same):
    assert same_program(["G90", old], ["G90", new]) is same


# --- a turning job drawn from a DXF: proved against its drawing record, not its params ----------

@pytest.mark.parametrize("workers", [1, 2])
def test_a_drawn_job_whose_params_left_its_drawing_record_is_named_not_proved(conn, seed_job, workers):
    """A runner's SQL can change a turning job's params after import; `engine instantiate --job`
    then refuses it, naming the drawing record it no longer agrees with, because the program is
    proved against the drawing as recorded (engine.programs.drawing_records). The impact proves a
    draft's program for the job the same way: a tool change position 1 mm off the drawing's is not
    proved as the job's own, and the job is named, as an old problem of the job (the released
    version fails it too), in one process and in workers."""
    gear_class = conn.execute("SELECT gear_class FROM job WHERE id = %s", (seed_job,)).fetchone()[0]
    recorded = conn.execute("SELECT (params->>'tool_change_x')::float FROM job WHERE id = %s",
                            (seed_job,)).fetchone()[0]
    conn.execute("UPDATE job SET params = jsonb_set(params, '{tool_change_x}', to_jsonb(%s::float)) WHERE id = %s",
                 (recorded + 1.0, seed_job))
    edit(conn, gear_class, 150, o='"G21 G18 G40 G90 "')    # a draft that changes every program of the class
    report = impact(conn, gear_class, workers=workers)
    failures = [failure for failure in report.failures if failure.job_id == seed_job]
    assert len(failures) == 1, report.failures
    assert f"params.tool_change_x = {recorded + 1.0:g}" in failures[0].error, failures[0].error
    assert "drawing record" in failures[0].error and not failures[0].released_makes
