"""`engine instantiate --class C --params P` (issue 17) as a user meets it, on real programs: an
imported program comes back from its class with its own parameters, and with new values exactly
the words bound to them change; the machine's verifier reads it, and what it cannot read (a dialect
it has no grammar for, a program it refuses) is refused with one line and nothing stored, or stored
with --unverified, marked UNVERIFIED in its lineage line and record and never written to a file.

The verified chain is real end to end: a real lathe drawing becomes a turning job (import-dxf), its
program is written to a file on the ISO lathe, and that file is imported (import-nc) as a class.
The refused and unverified paths take real foreign programs (tests/data/nc)."""
from __future__ import annotations

import json
import re

import psycopg
import pytest
from helpers.class_jobs import DATA, LINEAGE_ROW, PAWN, SPEED, import_emco, ok, refused, stored_program
from helpers.releases import release_draft
from psycopg import errors
from psycopg.types.json import Jsonb

CAM = DATA / "nc" / "sinumerik" / "cam_840dsl" / "CAM_TEST.MPF"   # 840D sl CAM output
EMCO_CNC = DATA / "nc" / "emco_from_dxf" / "testNegDXF.cnc"   # Emco fixed-column format
# A LinuxCNC lathe as a shop would record it: a dialect the verifier has no grammar for.
LINUXCNC_LATHE = ("INSERT INTO machine (name, kind, dialect, x_min, x_max, z_min, z_max, spindle_max) "
                  "VALUES ('lathe-fagor', 'lathe', 'fagor', 0, 400, -600, 200, 4000)")
SUBMIT = ("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
          "row_ids, trace, unverified) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, %s)")


def stored_counts(url) -> tuple[int, int]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


# --- verified: the imported program again, and new values --------------------------------------------

@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_class_of_an_imported_program_gives_it_back_with_its_own_parameters(run, tmp_path):
    source, lines = import_emco(run, tmp_path)
    before = stored_counts(run.url)
    made = ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft"))
    assert stored_counts(run.url) == (before[0] + 1, before[1] + 1)
    with psycopg.connect(run.url) as conn:
        program_id, job = conn.execute("SELECT max(id), max(job_id) FROM program").fetchone()
        stored_job = conn.execute("SELECT gear_id, hob_id, gear_class, machine FROM job WHERE id = %s",
                                  (job,)).fetchone()
    assert stored_job == (None, None, "emco_neg", "lathe-iso")
    template_lines, lineage, unverified = stored_program(run.url, program_id)
    assert template_lines == lines
    with psycopg.connect(run.url) as conn:
        assert made.stdout.splitlines() == conn.execute("SELECT lines FROM program WHERE id = %s",
                                                        (program_id,)).fetchone()[0]   # printed as stored
    assert len(lineage) == 1 and lineage[0].startswith(f"(PROGRAM {program_id} TEMPLATE emco_neg v1 ")
    assert "UNVERIFIED" not in lineage[0] and unverified is False
    assert "(not in --params): " in made.stderr and {"speed", "feed", "program_name"} == set(
        made.stderr.split("(not in --params): ")[1].splitlines()[0].split(", "))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_new_values_change_exactly_the_words_bound_to_them_and_the_file_is_the_stored_program(run, tmp_path):
    """A lathe class job is proved by the turning simulation without a drawing record (issue 27):
    against a blank its params state (Ø26 from Z0 to Z-40), it is written to --out, and its notes
    say which checks did not run. Against a blank assumed from its own cuts it is refused a file
    (the adversary's rapid through bar the program never cuts would pass): nothing stored."""
    source, lines = import_emco(run, tmp_path)
    params = tmp_path / "new.json"
    new = {"speed": 800, "feed": {"value": 120.5, "addresses": ["F"]}}    # both forms
    params.write_text(json.dumps(new))
    out = tmp_path / "NEW.NC"
    with psycopg.connect(run.url) as conn:
        release_draft(conn, "emco_neg")   # a draft's program never reaches a file (issue 26)
    before = stored_counts(run.url)
    message = refused(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--params", params,
                          "--out", out))
    assert "assumed from its own cuts" in message and "stock_diameter, stock_z_front and stock_z_back" in message
    assert stored_counts(run.url) == before and not out.exists()
    params.write_text(json.dumps({**new, "stock_diameter": 26, "stock_z_front": 0, "stock_z_back": -40}))
    made = json.loads(ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso",
                             "--params", params, "--out", out, "--json")).stdout)
    new_words = {f"S{SPEED}": "S800", "F150.000": "F120.500"}
    expected = [" ".join(new_words.get(word, word) for word in line.split(" ")) for line in lines]
    template_lines, lineage, unverified = stored_program(run.url, made["program_id"])
    assert template_lines == expected and sum(a != b for a, b in zip(expected, lines)) == 4
    assert (made["given"], made["taken"], made["unverified"]) == (
        ["speed", "feed", "stock_diameter", "stock_z_front", "stock_z_back"], ["program_name"], False)
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT lines FROM program WHERE id = %s", (made["program_id"],)).fetchone()[0]
    assert out.read_bytes() == ("\n".join(stored) + "\n").encode()   # through the writer, with the file's layout
    assert any(f"the blank Ø{26:.3f} Z{-40:.3f}…{0:.3f}:" in note for note in made["notes"]), made["notes"]
    assert any(note.startswith("not checked: a cut into the finished part") for note in made["notes"])
    again = json.loads(ok(run("instantiate", "--job", made["job_id"], "--draft", "--json")).stdout)
    assert stored_program(run.url, again["program_id"])[0] == expected   # the job made again, verified again


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("addresses", [["S"], ["F", "S"], ["X"]])
def test_a_bound_form_naming_addresses_the_class_does_not_bind_is_refused_naming_its_address(run, tmp_path,
                                                                                               addresses):
    """The class was imported with feed bound wherever the file wrote 150 (only at F150.000, as
    import_emco checks in the file): a file asking for the feed at other addresses asks for a program
    the class cannot make, and is refused naming F, not made at F alone."""
    import_emco(run, tmp_path)
    before = stored_counts(run.url)
    params = tmp_path / "other.json"
    params.write_text(json.dumps({"feed": {"value": 100, "addresses": addresses}}))
    refusal = refused(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft",
                          "--params", params))
    assert "feed is bound at F in class emco_neg" in refusal and '["F"]' in refusal
    assert stored_counts(run.url) == before


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_bound_form_naming_the_class_s_address_in_lower_case_is_the_class_s_binding(run, tmp_path):
    source, lines = import_emco(run, tmp_path)
    params = tmp_path / "lower.json"
    params.write_text(json.dumps({"feed": {"value": 100, "addresses": ["f"]}}))
    made = ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft", "--params", params,
                  "--dry-run"))
    assert sum("F100.000" in line.split(" ") for line in made.stdout.splitlines()) == \
        sum("F150.000" in line.split(" ") for line in lines) > 0


@pytest.mark.parametrize("gear_class", ["c_1", "c", "x9", "a" * 63])
def test_a_class_imported_without_a_program_name_gets_an_840d_program_name_for_any_class_name(run, gear_class):
    """import-nc accepts these class names (a lower-case letter, then letters, digits, _, 63 at
    most); the class's name in capitals is no 840D program name when its second character is no
    letter or it is longer than 24 (§A1), and the job must not be refused for a name the user never
    gave. (A real LinuxCNC program, stored unverified: its header names no program.)"""
    with psycopg.connect(run.url) as conn:
        conn.execute(LINUXCNC_LATHE)
    ok(run("import-nc", PAWN, "--class", gear_class))
    ok(run("instantiate", "--class", gear_class, "--machine", "lathe-fagor", "--draft", "--unverified"))
    with psycopg.connect(run.url) as conn:
        name = conn.execute("SELECT name FROM program ORDER BY id DESC LIMIT 1").fetchone()[0]
    assert re.fullmatch(r"(?:[A-Z]{2}|_[A-Z])[A-Z0-9_]{0,22}", name), name   # §A1, in capitals like the class
    assert name.lstrip("_") == gear_class.upper()[:len(name.lstrip("_"))]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_dry_run_of_a_class_job_with_csv_parameters_prints_the_program_and_stores_nothing(run, tmp_path):
    source, lines = import_emco(run, tmp_path)
    params = tmp_path / "new.csv"
    params.write_text("name,value\nspeed,700\n")
    before = stored_counts(run.url)
    dry = ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft", "--dry-run",
                 "--params", params))
    assert "(PROGRAM DRY-RUN TEMPLATE emco_neg v1 " in dry.stdout and "nothing stored" in dry.stderr
    expected = [" ".join("S700" if word == f"S{SPEED}" else word for word in line.split(" ")) for line in lines]
    assert [line for line in dry.stdout.splitlines() if "PROGRAM DRY-RUN" not in line] == expected != lines
    assert stored_counts(run.url) == before


# --- refused -----------------------------------------------------------------------------------------------

def test_a_machine_whose_dialect_the_verifier_does_not_know_is_refused_and_nothing_is_stored(run):
    with psycopg.connect(run.url) as conn:
        conn.execute(LINUXCNC_LATHE)
    ok(run("import-nc", PAWN, "--class", "pawn"))
    before = stored_counts(run.url)
    message = refused(run("instantiate", "--class", "pawn", "--machine", "lathe-fagor", "--draft"))
    assert "'fagor'" in message and "lathe/iso" in message and "lathe/840d" in message
    assert stored_counts(run.url) == before


@pytest.mark.parametrize("path, machine, reason", [(CAM, "lathe-840d", "milling program"),
                                                   (EMCO_CNC, "lathe-iso", "not a word")],
                         ids=["840D sl CAM program", "Emco program"])
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_real_program_the_verifier_refuses_is_refused_with_its_reason(run, path, machine, reason):
    ok(run("import-nc", path, "--class", "foreign"))
    before = stored_counts(run.url)
    message = refused(run("instantiate", "--class", "foreign", "--machine", machine, "--draft"))
    lines = path.read_text().splitlines()
    number = int(re.search(r"FOREIGN line (\d+) ", message)[1])
    assert lines[number - 1].strip()[:20] in message and reason in message, message
    assert stored_counts(run.url) == before
    made = json.loads(ok(run("instantiate", "--class", "foreign", "--machine", machine, "--draft", "--unverified",
                             "--json")).stdout)
    template_lines, lineage, unverified = stored_program(run.url, made["program_id"])
    assert template_lines == lines and unverified and lineage[0].rstrip(")").endswith(" DRAFT UNVERIFIED")


def test_unknown_parameter_names_a_modelled_class_and_a_hobber_are_refused_naming_what_to_do(run, tmp_path):
    params = tmp_path / "pawn.json"
    params.write_text(json.dumps({"spindle": 1000, "feed": 50.0}))
    ok(run("import-nc", PAWN, "--class", "pawn", "--params", params))
    typo = tmp_path / "typo.json"
    typo.write_text(json.dumps({"spindel": 1200, "feed": 40.0}))
    before = stored_counts(run.url)
    refusals = {
        ("--class", "pawn", "--machine", "lathe-iso", "--params", typo): ["'spindel'", "feed, program_name, spindle"],
        ("--class", "spur", "--machine", "lathe-iso"): ["hobbing model", "--gear"],
        ("--class", "turning_iso", "--machine", "lathe-iso"): ["turning class", "import-dxf"],
        ("--class", "pawn", "--machine", "hobber-840d"): ["simulation", "gear and a hob"],
        ("--class", "pawn"): ["--machine",
                              "hobber-840d, hobber-fanuc, lathe-840d, lathe-fanuc-0t, lathe-iso, lathe-linuxcnc"],
        ("--class", "pawn", "--machine", "lathe-iso", "--cuts", "2"): ["--cuts", "--params"],
        ("--gear", "42", "--params", params): ["--params", "--class"],
        ("--gear", "42", "--unverified"): ["--unverified", "--class"],
    }
    for args, words in refusals.items():
        message = refused(run("instantiate", *args, "--draft"))
        assert all(word in message for word in words), (args, message)
    assert stored_counts(run.url) == before


# --- unverified ---------------------------------------------------------------------------------------------

def test_an_unverified_program_is_stored_and_shown_as_such_and_verified_when_made_again(run):
    with psycopg.connect(run.url) as conn:
        conn.execute(LINUXCNC_LATHE)
    ok(run("import-nc", PAWN, "--class", "pawn"))
    made = ok(run("instantiate", "--class", "pawn", "--machine", "lathe-fagor", "--draft", "--unverified"))
    assert "UNVERIFIED" in made.stderr.splitlines()[-1]
    with psycopg.connect(run.url) as conn:
        program_id, job_id = conn.execute("SELECT id, job_id FROM program ORDER BY id DESC LIMIT 1").fetchone()
    template_lines, lineage, unverified = stored_program(run.url, program_id)
    assert template_lines == PAWN.read_text().splitlines() and unverified is True
    assert lineage == [made.stdout.splitlines()[0]] and lineage[0].endswith(" DRAFT UNVERIFIED")
    listed = json.loads(ok(run("programs", "list", "--json")).stdout)["programs"]
    assert [(p["program_id"], p["unverified"]) for p in listed if p["unverified"]] == [(program_id, True)]
    table = ok(run("programs", "list", "--class", "pawn")).stdout
    assert "UNVERIFIED" in table
    shown = ok(run("programs", "show", program_id)).stdout
    assert "verifier:      UNVERIFIED" in shown
    assert json.loads(ok(run("programs", "show", program_id, "--json")).stdout)["programs"][0]["unverified"] is True
    before = stored_counts(run.url)
    remade = refused(run("instantiate", "--job", job_id, "--draft"))   # made again: read by the verifier
    assert "'fagor'" in remade and stored_counts(run.url) == before


def test_an_unverified_program_is_never_written_to_a_file(run, tmp_path):
    with psycopg.connect(run.url) as conn:
        conn.execute(LINUXCNC_LATHE)
    ok(run("import-nc", PAWN, "--class", "pawn"))
    before = stored_counts(run.url)
    out = tmp_path / "PAWN.NGC"
    message = refused(run("instantiate", "--class", "pawn", "--machine", "lathe-fagor", "--draft", "--unverified",
                          "--out", out))
    assert "never written to a file" in message and not out.exists()
    folder = tmp_path / "nc"
    run.config.write_text(f'machine = "lathe-fagor"\n\n[machines.lathe-fagor]\nout = "{folder}"\n')
    message = refused(run("instantiate", "--class", "pawn", "--draft", "--unverified"))   # the config's machine
    assert "never written to a file" in message and not folder.exists()
    assert stored_counts(run.url) == before
    help_text = " ".join(ok(run("instantiate", "--help")).stdout.split())
    assert "Never written to a file" in help_text and "a program that reaches the machine is one the verifier read" \
        in help_text


# --- the database holds the record and the lineage line together --------------------------------------------

def resubmit(conn, program_id: int, unverified: bool, lineage_of) -> None:
    """The stored program submitted again under a new id, its lineage line made by lineage_of."""
    job_id, gear_class, version, digest, name, lines, row_ids, trace = conn.execute(
        "SELECT job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace FROM program "
        "WHERE id = %s", (program_id,)).fetchone()
    new_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    lines = [lineage_of(text.replace(f"PROGRAM {program_id} ", f"PROGRAM {new_id} ")) if row == LINEAGE_ROW else text
             for text, row in zip(lines, row_ids)]
    conn.execute(SUBMIT, (new_id, job_id, gear_class, version, digest, name, lines, row_ids, Jsonb(trace),
                          unverified))


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_database_holds_the_unverified_word_to_the_record_and_refuses_it_for_hobbing(run):
    with psycopg.connect(run.url) as conn:
        conn.execute(LINUXCNC_LATHE)
    ok(run("import-nc", PAWN, "--class", "pawn"))
    unverified = json.loads(ok(run("instantiate", "--class", "pawn", "--machine", "lathe-fagor", "--draft",
                                   "--unverified", "--json")).stdout)["program_id"]
    hobbing = json.loads(ok(run("instantiate", "--gear", 42, "--json")).stdout)["program_id"]
    with psycopg.connect(run.url) as conn:
        resubmit(conn, unverified, True, lambda line: line)   # the record and its line agree
        for marked, lineage_of in ((False, lambda line: line), (True, lambda line: line[:-len(" UNVERIFIED")])):
            with pytest.raises(errors.CheckViolation, match="lineage line"), conn.transaction():
                resubmit(conn, unverified, marked, lineage_of)
        with pytest.raises(errors.CheckViolation, match="never stored unverified"), conn.transaction():
            resubmit(conn, hobbing, True, lambda line: line + " UNVERIFIED")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_lathe_class_job_made_again_is_proved_and_written_to_a_file(run, tmp_path):
    """`instantiate --job` of a lathe class job: proved by the turning simulation again, against
    the blank its --params stated (Ø26 from Z0 to Z-40: the program's rapids at X28 and up stay
    above it), and written; `engine simulate --program` says what it proved and what not."""
    import_emco(run, tmp_path)
    with psycopg.connect(run.url) as conn:
        release_draft(conn, "emco_neg")
    params = tmp_path / "blank.json"
    params.write_text(json.dumps({"stock_diameter": 26, "stock_z_front": 0, "stock_z_back": -40}))
    made = json.loads(ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--params", params,
                             "--json")).stdout)
    assert any(f"the blank Ø{26:.3f} Z{-40:.3f}…{0:.3f}:" in note for note in made["notes"]), made["notes"]
    out = tmp_path / "AGAIN.NC"
    again = json.loads(ok(run("instantiate", "--job", made["job_id"], "--out", out, "--json")).stdout)
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT lines FROM program WHERE id = %s", (again["program_id"],)).fetchone()[0]
    assert out.read_bytes() == ("\n".join(stored) + "\n").encode()
    simulated = ok(run("simulate", "--program", again["program_id"])).stdout.splitlines()
    assert simulated[-1].endswith(f"through the blank Ø{26:.3f} Z{-40:.3f}…{0:.3f}; clean")
    assert any(line.startswith("not checked: a cut into the finished part") for line in simulated)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_adversary_s_rapid_through_the_blank_in_an_imported_program_is_refused_naming_it(run, tmp_path):
    """The second adversary of issue 26 wrote G00 X0.000 Z-15.000 into an imported lathe program:
    the turning simulation follows it through the blank the program implies and refuses it, at
    every exit (with --out, without, a dry run): exit 1, one line naming the line, nothing stored."""
    source, lines = import_emco(run, tmp_path)
    first_approach = lines.index("G00 X124.000 Z2.000")
    evil = tmp_path / "evil.nc"
    evil.write_text("\n".join([*lines[:first_approach + 1], "G00 X0.000 Z-15.000", *lines[first_approach + 1:]])
                    + "\n")
    ok(run("import-nc", evil, "--class", "evil_neg", "--params", tmp_path / "params.json"))   # as import_emco
    with psycopg.connect(run.url) as conn:
        release_draft(conn, "evil_neg")
    before, out = stored_counts(run.url), tmp_path / "EVIL.NC"
    for more in (["--out", out], [], ["--dry-run"]):
        message = refused(run("instantiate", "--class", "evil_neg", "--machine", "lathe-iso", *more))
        assert f"line {first_approach + 2} 'G00 X0.000 Z-15.000'" in message, message
        assert "rapid through material" in message and "nothing stored" in message
    assert stored_counts(run.url) == before and not out.exists()
