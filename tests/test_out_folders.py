"""--out into a folder that does not exist (issue 31): refused in one line, exit 1, nothing stored
and no folder made, unless --mkdir (or `mkdir = true` in the command's table of the config file)
asks for it; for every command with --out: instantiate (one program, a batch), template export,
plot."""
from __future__ import annotations

import psycopg
import pytest

from engine.errors import EngineError
from engine.programs import outputs


def program_count(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


def one_line_refusal(result) -> str:
    assert result.exit_code == 1, result.output
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.output, result.stderr
    return result.stderr


@pytest.mark.parametrize("selection", [("--gear", "42"), ("--gears", "42-43")], ids=["one", "batch"])
@pytest.mark.parametrize("target", ["typo/", "typo/deeper/GEAR.MPF"], ids=["folder", "file"])
def test_instantiate_into_a_missing_folder_is_refused_and_stores_nothing(read_only_run, tmp_path, selection, target):
    before = program_count(read_only_run.url)
    message = one_line_refusal(read_only_run("instantiate", *selection, "--out", f"{tmp_path}/{target}"))
    assert "does not exist" in message and "nothing stored" in message and "--mkdir" in message
    assert program_count(read_only_run.url) == before
    assert list(tmp_path.iterdir()) == []


def test_instantiate_with_mkdir_makes_the_folders(run, tmp_path):
    made = run("instantiate", "--gears", "42-43", "--out", tmp_path / "new" / "deeper", "--mkdir")
    assert made.exit_code == 0, made.output
    assert sorted(path.name for path in (tmp_path / "new" / "deeper").iterdir()) == ["GEAR42.MPF", "GEAR43.MPF"]


def test_the_config_file_can_ask_for_the_folder_to_be_made(run, tmp_path):
    run.config.write_text("[instantiate]\nmkdir = true\n")
    made = run("instantiate", "--gear", 42, "--out", f"{tmp_path}/new/")
    assert made.exit_code == 0, made.output
    assert [path.name for path in (tmp_path / "new").iterdir()] == ["GEAR42.MPF"]


def test_the_machine_folder_of_the_config_file_must_exist_too(read_only_run, tmp_path):
    read_only_run.config.write_text(f'[machines.hobber-840d]\nout = "{tmp_path}/share/hobber"\n')
    before = program_count(read_only_run.url)
    assert "does not exist" in one_line_refusal(read_only_run("instantiate", "--gear", 42))
    assert program_count(read_only_run.url) == before and list(tmp_path.iterdir()) == []


def test_mkdir_without_a_folder_to_make_is_refused(read_only_run):
    before = program_count(read_only_run.url)
    assert "give --out too" in one_line_refusal(read_only_run("instantiate", "--gear", 42, "--mkdir"))
    assert program_count(read_only_run.url) == before


def test_program_files_refuse_a_missing_folder_before_planning_anything(tmp_path):
    with pytest.raises(EngineError, match="does not exist; nothing stored"):
        outputs.ProgramFiles(tmp_path / "typo", batch=True).plan([("GEAR1", ["M30"])])
    assert outputs.ProgramFiles(tmp_path / "new", batch=True, mkdir=True).plan([("GEAR1", ["M30"])]) \
        == {"GEAR1": str(tmp_path / "new" / "GEAR1.MPF")}
    assert list(tmp_path.iterdir()) == []   # planned only: the folder is made when the files are written


def test_template_export_into_a_missing_folder(read_only_run, tmp_path):
    message = one_line_refusal(read_only_run("template", "export", "--class", "spur",
                                             "--out", tmp_path / "typo" / "spur.csv"))
    assert "does not exist" in message and list(tmp_path.iterdir()) == []
    made = read_only_run("template", "export", "--class", "spur", "--out", tmp_path / "new" / "spur.csv", "--mkdir")
    assert made.exit_code == 0, made.output
    assert (tmp_path / "new" / "spur.csv").read_text().startswith("id,")


def test_plot_into_a_missing_folder(run, tmp_path):
    stored = run("instantiate", "--gear", 42)
    assert stored.exit_code == 0, stored.output
    program = program_count(run.url)   # the seeded copy holds no other program
    message = one_line_refusal(run("plot", "--program", program, "-o", tmp_path / "typo" / "p.svg"))
    assert "does not exist" in message and list(tmp_path.iterdir()) == []
    made = run("plot", "--program", program, "-o", tmp_path / "new" / "p.svg", "--mkdir")
    assert made.exit_code == 0, made.output
    assert (tmp_path / "new" / "p.svg").is_file()
