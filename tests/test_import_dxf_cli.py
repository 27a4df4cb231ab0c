"""`engine import-dxf` and `engine plot` as a user meets them: every real drawing becomes a job
or is refused with the reader's reason, edits in SQL reach the program, pictures are written,
bad input gets one line, exit 1 and no job."""
from __future__ import annotations

import json

import psycopg
import pytest
from helpers.drawings import DXF, EMCO, REAL, seed_drawing
from helpers.outcomes import job_count, one_line_refusal

from engine.cli.app import main

PROFILE_ONLY = set(EMCO) | {"d2g_Turbocad_12.5_R14.dxf", "qcad_screw_R2007.dxf", "ezdxf_AC1003_LINE_Example.dxf",
                            "d2g_132_R14.dxf", "d2g_132_R2000.dxf", "d2g_132_R2004.dxf",
                            "scadchess_king_profile_R2007.dxf", "scadchess_pawn_profile_R2007.dxf",
                            "scadchess_queen_profile_R2007.dxf"}
# The chess pieces are Ø108 … Ø174: at the default 800 r/min the cutting speed is above the
# carbide-on-steel window (a true refusal), so they are turned slower and in deeper cuts.
CUTTING = {name: ("--rough-depth", "3", "--speed", "500") for name in PROFILE_ONLY if name.startswith("scadchess")}
# Read, but no part a lathe turns from outside, refused as a job with the reason. d2g_132: a closed
# outline on layer '81' (1400 drawing units, refused before its size is) with notches 31 … 91 along
# its edge on the axis: drawn along Z (R14, R2000) the notch is a bore; drawn turned by 90° (R2004)
# a gap under material. The AC1003 bracket on layer '1' meets the axis only at X 1.5 … 2: either
# side, its section (Y 1 … 1.5) is a ring.
NOT_TURNED_FROM_OUTSIDE = {"d2g_132_R14.dxf": "internal turning is not supported",
                           "d2g_132_R2000.dxf": "internal turning is not supported",
                           "d2g_132_R2004.dxf": "an external tool cannot reach",
                           "ezdxf_AC1003_LINE_Example.dxf": "internal turning is not supported"}


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_every_real_drawing_becomes_a_job_or_is_refused_with_its_reason(run):
    assert {name for name, (_, refusal) in REAL.items() if refusal is None} == PROFILE_ONLY
    for name, (_, refusal) in sorted(REAL.items()):
        before = job_count(run.url)
        result = run("import-dxf", DXF / name)
        message = one_line_refusal(result)
        assert job_count(run.url) == before, name
        if refusal is not None:
            assert refusal in message, (name, message)
            continue
        assert "--rough-depth" in message, (name, message)
        cutting = CUTTING.get(name, ("--rough-depth", "1"))
        unnamed = run("import-dxf", DXF / name, *cutting, "--machine", "lathe-840d")
        if unnamed.exit_code == 0:   # a file name that makes an 840D program name (QCAD_SCREW_R2007)
            before += 1
        else:   # the others' file names make no 840D name: on an 840D lathe one must be given
            refused = one_line_refusal(unnamed)
            assert ("840D lathe the name is the program" in refused and "--program-name" in refused) \
                or name in NOT_TURNED_FROM_OUTSIDE, (name, refused)
        assert job_count(run.url) == before, name
        made = run("import-dxf", DXF / name, *cutting, "--program-name", "DRAWN_PART", "--json")
        if name in NOT_TURNED_FROM_OUTSIDE:
            assert NOT_TURNED_FROM_OUTSIDE[name] in made.output, (name, made.output)
            assert made.exit_code == 1 and job_count(run.url) == before, name
            continue
        assert made.exit_code == 0, (name, made.output)
        job_id = json.loads(made.stdout)["job_id"]
        assert job_count(run.url) == before + 1
        program = run("instantiate", "--job", job_id, "--json")
        assert program.exit_code == 0, (name, program.output)
        assert json.loads(program.stdout)["lines"] > 10


def test_import_reports_the_job_operations_and_what_was_assumed(run, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    result = run("import-dxf", tmp_path / "part.dxf", "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert {"job_id", "operations", "repairs", "notes"} <= report.keys()
    assert [(op["operation"], op["kind"]) for op in report["operations"]] == [(1, "ROUGH"), (2, "SLOT"), (3, "THREAD")]
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT gear_id, gear_class, machine, params->>'drawing' FROM job WHERE id = %s",
                              (report["job_id"],)).fetchone()
    assert stored == (None, "turning_iso", "lathe-iso", "part.dxf")
    emco = run("import-dxf", DXF / EMCO[0], "--speed", "600", "--program-name", "EMCO_NEG")
    assert emco.exit_code == 0 and emco.stdout.startswith("job ")
    assert "no tool-change POINT" in emco.stderr and "mirrored" in emco.stderr


def feed_words(lines: list[str]) -> list[tuple[int, str]]:
    return [(number, word) for number, line in enumerate(lines) for word in line.split() if word.startswith("F")]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_feed_edited_in_sql_changes_exactly_that_operation_s_f_words(run, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    job_id = json.loads(run("import-dxf", tmp_path / "part.dxf", "--json").stdout)["job_id"]
    before = run("instantiate", "--job", job_id).stdout.splitlines()
    with psycopg.connect(run.url) as conn:
        conn.execute("""UPDATE job SET module_params = jsonb_set(module_params, '{cutmotion:2,feed}', '25')
                        WHERE id = %s""", (job_id,))
    after = run("instantiate", "--job", job_id).stdout.splitlines()
    assert len(after) == len(before)
    changed = [(b, a) for b, a in zip(before, after) if b != a]
    lineage = [(b, a) for b, a in changed if b.lstrip("(; ").startswith("PROGRAM ")]   # a new program, new INPUT
    assert len(lineage) == 1 and lineage[0][0].split(" INPUT ")[1] != lineage[0][1].split(" INPUT ")[1]
    assert [pair for pair in changed if pair not in lineage] == [("G98 F20.000", "G98 F25.000")]
    assert {word for _, word in feed_words(after)} - {word for _, word in feed_words(before)} == {"F25.000"}


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_plot_writes_a_picture_of_the_job(run, tmp_path):
    job_id = json.loads(run("import-dxf", DXF / EMCO[1], "--rough-depth", "1", "--program-name", "EMCO_G02",
                            "--json").stdout)["job_id"]
    result = run("plot", "--job", job_id, "-o", tmp_path / "job.png")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "job.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert "ROUGH" in result.stdout and "FINISH" in result.stdout
    refused = run("plot", "--job", job_id, "-o", tmp_path / "job.jpg")
    assert "png" in one_line_refusal(refused)


def test_bad_inputs_get_one_line_exit_1_and_no_job(run, tmp_path):
    seed_drawing(tmp_path / "part.dxf")
    seed_drawing(tmp_path / "bad_code.dxf", rough_codes="@GROUGH @Sfast @T01")
    whole = (DXF / EMCO[1]).read_bytes()
    (tmp_path / "half.dxf").write_bytes(whole[: len(whole) // 2])
    before = job_count(run.url)
    cases = [
        ((tmp_path / "missing.dxf",), "no such file"),
        ((tmp_path / "half.dxf",), "truncated DXF"),
        ((tmp_path / "bad_code.dxf",), "bad value 'fast' for @S"),
        ((tmp_path / "part.dxf", "--machine", "nope"), "machine 'nope' does not exist"),
        ((tmp_path / "part.dxf", "--machine", "hobber-840d"), "not a lathe"),
        ((tmp_path / "part.dxf", "--alternate", "1,2"), "operation 2 is not a present ROUGH operation"),
        ((tmp_path / "part.dxf", "--rough-depth", "2"), "profile-only drawings"),
    ]
    for args, words in cases:
        message = one_line_refusal(run("import-dxf", *args))
        assert words in message, (args, message)
    assert job_count(run.url) == before


def test_help_explains_every_option(read_only_run):
    for command in ("import-dxf", "plot"):
        result = read_only_run(command, "--help")
        assert result.exit_code == 0
        options = [param for param in main.commands[command].params if param.param_type_name == "option"]
        assert all(option.help for option in options), command
    text = read_only_run("import-dxf", "--help").output
    for words in ("--rough-depth", "default: 1", "--alternate", "--stock-diameter", "lathe-840d", "@-codes"):
        assert words in text, words
