"""Program files in --out (issue 13): they land only inside --out, replace an existing file only
with --force, take the user's umask, and appear only after their programs are committed; a
kill -9 in the middle of a batch's files leaves every file equal to a committed program and no
temporary file."""
from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import psycopg
import pytest

from engine.errors import EngineError
from engine.programs import outputs
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import Output

REPOSITORY = Path(__file__).resolve().parent.parent


def program_count(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def committed_texts(url) -> dict[str, list[bytes]]:
    """Every committed program's file text, by program name."""
    texts: dict[str, list[bytes]] = {}
    with psycopg.connect(url) as conn:
        for name, lines in conn.execute("SELECT name, lines FROM program ORDER BY id"):
            texts.setdefault(name, []).append(("\n".join(lines) + "\n").encode("ascii"))
    return texts


def latest_text(url, name: str) -> bytes:
    return committed_texts(url)[name][-1]


def everything_under(folder: Path) -> list[str]:
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*"))


def one_line_refusal(result) -> str:
    assert result.exit_code == 1, result.output
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    return result.stderr.strip()


def a_job_named(url, name: str) -> int:
    """A stored job of gear 42 whose program_name is set to `name`, past the database's own check
    (as in a database where it got in before the check existed): the file layer must stand alone."""
    with psycopg.connect(url) as conn:
        conn.execute("ALTER TABLE job DROP CONSTRAINT job_safe_params")
        conn.execute("ALTER TABLE program DROP CONSTRAINT program_safe_name")
        job_id = conn.execute("SELECT id FROM job ORDER BY id DESC LIMIT 1").fetchone()[0]
        conn.execute("UPDATE job SET params = jsonb_set(params, '{program_name}', to_jsonb(%s::text)) WHERE id = %s",
                     (name, job_id))
    return job_id


@pytest.mark.parametrize("name", ["../../x", "../x", "sub/GEAR42", "/tmp/GEAR42", ".."])
def test_a_program_name_that_leaves_out_is_refused_and_nothing_is_stored(run, tmp_path, name):
    assert run("instantiate", "--gear", 42).exit_code == 0
    job_id = a_job_named(run.url, name)
    out = tmp_path / "deep" / "er" / "out"
    out.mkdir(parents=True)
    before = program_count(run.url)
    for extra in ((), ("--force",)):
        # the verifier (its %_N_ header) or the file layer refuses it first; the file layer alone: below
        message = one_line_refusal(run("instantiate", "--jobs", f"{job_id}-{job_id}", "--out", out, *extra))
        assert "not a safe program name" in message or "%_N_" in message
        message = one_line_refusal(run("instantiate", "--job", job_id, "--out", out / "..", *extra))
        assert "not a safe program name" in message or "%_N_" in message
    assert program_count(run.url) == before
    assert everything_under(tmp_path) == ["deep", "deep/er", "deep/er/out"]


def test_the_file_layer_refuses_a_name_outside_out_by_itself(tmp_path):
    for name in ("../../x", "a/b", "GEAR42\nG0 X9999", ""):
        with pytest.raises(EngineError, match="not a safe program name"):
            outputs.ProgramFiles(tmp_path).plan([(name, ["M30"]), ("GEAR1", ["M30"])])
    assert everything_under(tmp_path) == []


def test_an_existing_file_is_replaced_only_with_force(run, tmp_path):
    (tmp_path / "GEAR42.MPF").write_text("; the program the operator has\n")
    (tmp_path / "GEAR43.MPF").write_text("; another\n")
    before = program_count(run.url)
    message = one_line_refusal(run("instantiate", "--gears", "42-44", "--out", tmp_path))
    assert str(tmp_path / "GEAR42.MPF") in message and "--force" in message and "nothing stored" in message
    message = one_line_refusal(run("instantiate", "--gear", 42, "--out", tmp_path / "GEAR42.MPF"))
    assert str(tmp_path / "GEAR42.MPF") in message and "--force" in message
    assert program_count(run.url) == before
    assert (tmp_path / "GEAR42.MPF").read_text() == "; the program the operator has\n"
    assert everything_under(tmp_path) == ["GEAR42.MPF", "GEAR43.MPF"]

    assert "give --out too" in one_line_refusal(run("instantiate", "--gear", 42, "--force"))
    assert run("instantiate", "--gears", "42-44", "--out", tmp_path, "--force").exit_code == 0
    assert program_count(run.url) == before + 3
    for name in ("GEAR42", "GEAR43", "GEAR44"):
        assert (tmp_path / f"{name}.MPF").read_bytes() == latest_text(run.url, name)
    assert everything_under(tmp_path) == ["GEAR42.MPF", "GEAR43.MPF", "GEAR44.MPF"]


@pytest.mark.parametrize("out", ["newdir/", "newdir"])
def test_a_batch_of_one_program_writes_into_the_folder_out_made_with_mkdir(run, tmp_path, out):
    made = run("instantiate", "--gears", "42-42", "--out", f"{tmp_path}/{out}", "--mkdir")
    assert made.exit_code == 0, made.output
    assert (tmp_path / "newdir").is_dir() and everything_under(tmp_path / "newdir") == ["GEAR42.MPF"]
    with psycopg.connect(run.url) as conn:
        job = conn.execute("SELECT max(id) FROM job").fetchone()[0]
    again = run("instantiate", "--jobs", f"{job}-{job}", "--out", f"{tmp_path}/again{out.removeprefix('newdir')}",
                "--mkdir")
    assert again.exit_code == 0, again.output
    assert everything_under(tmp_path / "again") == ["GEAR42.MPF"]
    assert (tmp_path / "again" / "GEAR42.MPF").read_bytes() == latest_text(run.url, "GEAR42")


def test_one_program_goes_into_a_folder_out_ending_with_a_slash_else_into_the_file_out(run, tmp_path):
    assert run("instantiate", "--gear", 42, "--out", f"{tmp_path}/folder/", "--mkdir").exit_code == 0
    assert run("instantiate", "--gear", 42, "--out", tmp_path / "GEAR42.MPF").exit_code == 0
    assert everything_under(tmp_path) == ["GEAR42.MPF", "folder", "folder/GEAR42.MPF"]


def test_a_file_naming_the_same_program_in_other_case_is_never_replaced(read_only_run, tmp_path):
    (tmp_path / "gear42.MPF").write_text("; written by hand\n")
    before = program_count(read_only_run.url)
    for extra in ((), ("--force",)):
        message = one_line_refusal(read_only_run("instantiate", "--gears", "42-43", "--out", tmp_path, *extra))
        assert "gear42.MPF" in message and "same program" in message
    assert program_count(read_only_run.url) == before and everything_under(tmp_path) == ["gear42.MPF"]


def test_the_file_layer_refuses_two_programs_of_one_batch_differing_only_in_case(tmp_path):
    with pytest.raises(EngineError, match="would replace each other"):
        outputs.ProgramFiles(tmp_path).plan([("PART7", ["M30"]), ("part7", ["M30"])])
    assert everything_under(tmp_path) == []


def test_two_programs_of_one_batch_differing_only_in_case_are_refused(run, tmp_path):
    """Two gears' jobs renamed PART7 and part7: refused before any file (by the job's name check,
    or by the file layer's), nothing stored."""
    assert run("instantiate", "--gears", "42-43").exit_code == 0
    with psycopg.connect(run.url) as conn:
        jobs = [row[0] for row in conn.execute("SELECT id FROM job ORDER BY id")]
        for job, name in zip(jobs, ("PART7", "part7")):   # a part number each, differing only in case
            conn.execute("UPDATE job SET params = jsonb_set(params, '{program_name}', %s) WHERE id = %s",
                         (json.dumps(name), job))
    before = program_count(run.url)
    refused = run("instantiate", "--jobs", f"{jobs[0]}-{jobs[1]}", "--out", tmp_path / "out")
    assert refused.exit_code == 1 and "Traceback" not in refused.output   # each bad job named (issue 16)
    message = refused.stderr
    assert "would replace each other" in message or "is the name of gear 43's program" in message
    assert program_count(run.url) == before and everything_under(tmp_path) == []


@pytest.fixture
def umask():
    """Set the process's umask for the test (the CLI runs in this process); restored after."""
    previous = os.umask(0o022)
    yield os.umask
    os.umask(previous)


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o027, 0o640), (0o002, 0o664)])
def test_files_take_the_user_s_umask(run, tmp_path, umask, mask, mode):
    umask(mask)
    assert run("instantiate", "--gears", "42-43", "--out", tmp_path / "batch", "--mkdir").exit_code == 0
    assert run("instantiate", "--gear", 44, "--out", tmp_path / "one.MPF").exit_code == 0
    files = [tmp_path / "batch" / "GEAR42.MPF", tmp_path / "batch" / "GEAR43.MPF", tmp_path / "one.MPF"]
    assert [stat.S_IMODE(path.stat().st_mode) for path in files] == [mode] * 3


def test_without_o_tmpfile_files_are_the_same_and_no_temporary_stays(run, tmp_path, umask, monkeypatch):
    monkeypatch.delattr(os, "O_TMPFILE")   # file systems without it: a hidden temporary, then its name
    umask(0o027)
    (tmp_path / "GEAR43.MPF").write_text("; old\n")
    assert one_line_refusal(run("instantiate", "--gears", "42-43", "--out", tmp_path)).endswith("or another --out")
    assert run("instantiate", "--gears", "42-43", "--out", tmp_path, "--force").exit_code == 0
    assert everything_under(tmp_path) == ["GEAR42.MPF", "GEAR43.MPF"]
    for name in ("GEAR42", "GEAR43"):
        path = tmp_path / f"{name}.MPF"
        assert path.read_bytes() == latest_text(run.url, name) and stat.S_IMODE(path.stat().st_mode) == 0o640


REFUSE_AT_COMMIT = "RAISE EXCEPTION 'refused at commit'"
LOSE_THE_SERVER_AT_COMMIT = "PERFORM pg_terminate_backend(pg_backend_pid())"


def at_commit(url, statement: str) -> None:
    """A deferred constraint trigger on program: `statement` runs at COMMIT, after every other one."""
    with psycopg.connect(url) as conn:
        conn.execute("CREATE FUNCTION at_commit() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN "
                     + statement + "; RETURN NULL; END $$")
        conn.execute("CREATE CONSTRAINT TRIGGER at_commit AFTER INSERT ON program DEFERRABLE INITIALLY DEFERRED "
                     "FOR EACH ROW EXECUTE FUNCTION at_commit()")


def test_a_commit_that_fails_leaves_no_file(run, tmp_path):
    at_commit(run.url, REFUSE_AT_COMMIT)
    before = program_count(run.url)
    message = one_line_refusal(run("instantiate", "--gears", "42-44", "--out", tmp_path / "out", "--mkdir"))
    assert "refused the commit" in message and "no file written" in message
    one_line_refusal(run("instantiate", "--gear", 42, "--out", tmp_path / "one.MPF"))
    assert program_count(run.url) == before and everything_under(tmp_path) == []


def test_a_server_lost_at_commit_leaves_no_file(run, tmp_path):
    at_commit(run.url, LOSE_THE_SERVER_AT_COMMIT)
    before = program_count(run.url)
    message = one_line_refusal(run("instantiate", "--gears", "42-44", "--out", tmp_path / "out", "--mkdir"))
    assert "connection was lost while committing" in message and "no file written" in message
    assert program_count(run.url) == before and everything_under(tmp_path) == []


def test_files_are_refused_inside_a_caller_s_transaction(conn, tmp_path):
    """conn.transaction() there is only a savepoint: files written then would precede the COMMIT."""
    with pytest.raises(EngineError, match="only after their programs are committed"):
        instantiate_gear(conn, 42, output=Output(tmp_path / "GEAR42.MPF"))
    assert instantiate_gear(conn, 42).lines[-1] == "M30"   # without files, a savepoint is all it needs
    assert everything_under(tmp_path) == []


def test_a_committed_program_is_what_its_file_holds(fresh_database_url, tmp_path):
    with psycopg.connect(fresh_database_url) as conn:
        program = instantiate_gear(conn, 42, output=Output(tmp_path / "GEAR42.MPF"))
    assert (tmp_path / "GEAR42.MPF").read_bytes() == latest_text(fresh_database_url, "GEAR42")
    assert program.path == str(tmp_path / "GEAR42.MPF")


BATCH_GEARS = 1500   # copies of gear 42: enough that the files of the batch take a while to write


def many_gears(url, count: int) -> None:
    with psycopg.connect(url) as conn:
        conn.execute("""
            INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width,
                              tip_diameter, root_diameter, cone_angle, crowning, material, hardness,
                              quality_grade, quantity)
            SELECT g, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, tip_diameter,
                   root_diameter, cone_angle, crowning, material, hardness, quality_grade, quantity
            FROM gear, generate_series(100000, 100000 + %s - 1) AS g WHERE id = 42""", (count,))


@pytest.mark.slow
def test_kill_9_during_the_files_of_a_batch_leaves_only_committed_programs_files(fresh_database_url, tmp_path):
    many_gears(fresh_database_url, BATCH_GEARS)
    out = tmp_path / "out"
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(REPOSITORY),
                                                                             os.environ.get("PYTHONPATH")]))}
    engine = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", fresh_database_url, "instantiate",
                               "--all", "--out", str(out), "--mkdir"], env=environment, stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True)
    try:
        while engine.poll() is None and not (out.is_dir() and any(out.iterdir())):
            time.sleep(0.0005)   # polling, not a timed assertion: kill as soon as the first file is there
        engine.send_signal(signal.SIGKILL)
    finally:
        _, errors = engine.communicate()
    committed = committed_texts(fresh_database_url)
    left = sorted(os.listdir(out)) if out.is_dir() else []
    assert left, f"the engine ended before writing a file: {errors}"
    assert [name for name in left if not name.endswith(".MPF") or name.startswith(".")] == []   # no temporary
    for name in left:
        assert (out / name).read_bytes() in committed.get(name.removesuffix(".MPF"), []), name
    with psycopg.connect(fresh_database_url) as conn:   # a file there: the whole batch was committed first
        gears = conn.execute("SELECT count(*) FROM gear").fetchone()[0]
    assert sum(len(texts) for texts in committed.values()) == gears >= BATCH_GEARS
