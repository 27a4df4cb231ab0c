"""Replacing program files (issue 26, finding 10): an old file stays until the new one takes its
name, a run whose files fail after the COMMIT leaves every earlier file as it was, a folder or
link swapped between the plan and the files is refused, and the exit code says "stored, not
written" (3) apart from "nothing stored" (1), naming the stored programs and the files.

What happens between the COMMIT and the files is set up by wrapping ProgramFiles.write: the
plan has seen the folder as it was, the programs are committed, and then the folder changes (an
operator, a full disk, another process) before or while the files are written."""
from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import psycopg
import pytest

from engine.programs import outputs

GEARS = ("GEAR42", "GEAR43", "GEAR44")
OLD = {name: f"; the program {name} the operator has\n".encode() for name in GEARS}


def old_files(folder: Path) -> None:
    folder.mkdir(exist_ok=True)
    for name, text in OLD.items():
        (folder / f"{name}.MPF").write_bytes(text)


def everything_in(folder: Path) -> list[str]:
    return sorted(os.listdir(folder))


def stored(url, count: int) -> dict[str, int]:
    """{program name: id} of the `count` programs stored last."""
    with psycopg.connect(url) as conn:
        rows = conn.execute("SELECT name, id FROM program ORDER BY id DESC LIMIT %s", (count,)).fetchall()
    return dict(rows)


def latest_text(url, name: str) -> bytes:
    with psycopg.connect(url) as conn:
        lines = conn.execute("SELECT lines FROM program WHERE name = %s ORDER BY id DESC LIMIT 1",
                             (name,)).fetchone()[0]
    return ("\n".join(lines) + "\n").encode("ascii")


def program_count(url) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


@pytest.fixture
def after_plan(monkeypatch):
    """after_plan(action): action(files) runs after the COMMIT, just before the files are written."""
    def install(action):
        original = outputs.ProgramFiles.write

        def write(files):
            action(files)
            return original(files)
        monkeypatch.setattr(outputs.ProgramFiles, "write", write)
    return install


def disk_full_at(call: int, monkeypatch):
    """os.write fails with ENOSPC from its `call`-th use on (the files' data), as a full disk does."""
    real_write, calls = os.write, []

    def write(descriptor, data):
        calls.append(descriptor)
        if len(calls) >= call:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write(descriptor, data)
    monkeypatch.setattr(os, "write", write)


def a_folder_in_the_way(folder: Path, monkeypatch) -> None:
    (folder / "GEAR43.MPF").unlink()
    (folder / "GEAR43.MPF").mkdir()


@pytest.mark.parametrize("failure", ["disk full at the second file", "a folder where the second file goes"])
def test_a_failed_force_batch_leaves_every_earlier_file_as_it_was(run, tmp_path, after_plan, monkeypatch, failure):
    out = tmp_path / "out"
    old_files(out)
    before = program_count(run.url)
    if failure.startswith("disk full"):
        after_plan(lambda files: disk_full_at(2, monkeypatch))
    else:
        after_plan(lambda files: a_folder_in_the_way(out, monkeypatch))
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    monkeypatch.undo()
    assert result.exit_code == 3, result.output
    assert program_count(run.url) == before + 3   # committed: the programs are stored
    assert everything_in(out) == ["GEAR42.MPF", "GEAR43.MPF", "GEAR44.MPF"]   # no temporary left
    for name in ("GEAR42", "GEAR44"):
        assert (out / f"{name}.MPF").read_bytes() == OLD[name], name
    if failure.startswith("disk full"):
        assert (out / "GEAR43.MPF").read_bytes() == OLD["GEAR43"]
    message = result.stderr
    ids = stored(run.url, 3)
    assert "Traceback" not in result.output and "every file there is as it was" in message
    assert f"programs {ids['GEAR42']}–{ids['GEAR44']} are stored" in message
    for name in GEARS:
        assert f"not written: {out / name}.MPF (program {ids[name]})" in message


def test_one_program_stored_not_written_is_exit_3_in_json_too(run, tmp_path, after_plan, monkeypatch):
    target = tmp_path / "GEAR42.MPF"
    target.write_bytes(OLD["GEAR42"])
    after_plan(lambda files: disk_full_at(1, monkeypatch))
    result = run("instantiate", "--gear", 42, "--out", target, "--force", "--json")
    monkeypatch.undo()
    assert result.exit_code == 3, result.output
    said = json.loads(result.stderr)
    program_id = stored(run.url, 1)["GEAR42"]
    assert said["exit"] == 3 and f"program {program_id} is stored" in said["error"]
    assert f"not written: GEAR42.MPF (program {program_id})" in said["error"]
    assert os.strerror(errno.ENOSPC) in said["error"]
    assert target.read_bytes() == OLD["GEAR42"] and everything_in(tmp_path) == ["GEAR42.MPF"]


def test_nothing_stored_stays_exit_1_and_leaves_the_files(run, tmp_path):
    """A bad gear in the batch: refused before storing (exit 1), the files untouched."""
    out = tmp_path / "out"
    old_files(out)
    before = program_count(run.url)
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET module = 40 WHERE id = 43")   # beyond the machine's maximum module
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    assert result.exit_code == 1 and "nothing stored" in result.stderr
    assert program_count(run.url) == before
    assert {name: (out / f"{name}.MPF").read_bytes() for name in GEARS} == OLD


def test_an_old_file_is_never_missing_nor_partial_while_it_is_replaced(run, tmp_path, after_plan, monkeypatch):
    """At every step that names, renames or removes a file, each target holds either its old
    bytes or its complete new bytes: an operator loading it at any moment gets a whole program."""
    out = tmp_path / "out"
    old_files(out)
    inodes = {name: (out / f"{name}.MPF").stat().st_ino for name in GEARS}
    seen_wrong: list[str] = []

    def watch(files):
        new = {target.name: data for target, data in files.texts.items()}

        def check(step):
            for name in GEARS:
                path = out / f"{name}.MPF"
                if not path.exists():
                    seen_wrong.append(f"{step}: {name} missing")
                elif path.read_bytes() not in (OLD[name], new[path.name]):
                    seen_wrong.append(f"{step}: {name} partial")

        for step in ("link", "rename", "replace", "unlink", "close", "fsync"):
            real = getattr(os, step)

            def watched(*args, _real=real, _step=step, **kwargs):
                check(_step)
                return _real(*args, **kwargs)
            monkeypatch.setattr(os, step, watched)
    after_plan(watch)
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    monkeypatch.undo()
    assert result.exit_code == 0, result.output
    assert seen_wrong == []
    for name in GEARS:
        path = out / f"{name}.MPF"
        assert path.read_bytes() == latest_text(run.url, name) and path.stat().st_ino != inodes[name]
    assert everything_in(out) == ["GEAR42.MPF", "GEAR43.MPF", "GEAR44.MPF"]


def test_a_failure_among_the_renames_says_exactly_which_files_were_replaced(run, tmp_path, after_plan,
                                                                               monkeypatch):
    out = tmp_path / "out"
    old_files(out)

    def second_rename_fails(files):
        real, calls = os.replace, []

        def replace(*args, **kwargs):
            calls.append(args)
            if len(calls) == 2:
                raise OSError(errno.EIO, os.strerror(errno.EIO))
            return real(*args, **kwargs)
        monkeypatch.setattr(os, "replace", replace)
    after_plan(second_rename_fails)
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    monkeypatch.undo()
    assert result.exit_code == 3, result.output
    ids = stored(run.url, 3)
    assert (out / "GEAR42.MPF").read_bytes() == latest_text(run.url, "GEAR42")
    assert [(out / f"{name}.MPF").read_bytes() for name in ("GEAR43", "GEAR44")] == [OLD["GEAR43"], OLD["GEAR44"]]
    assert everything_in(out) == ["GEAR42.MPF", "GEAR43.MPF", "GEAR44.MPF"]   # no temporary left
    message = result.stderr
    assert "replaced or written: GEAR42.MPF." in message
    assert f"{out / 'GEAR43.MPF'}: {os.strerror(errno.EIO)}" in message
    assert f"not written: {out}/GEAR43.MPF (program {ids['GEAR43']})" in message
    assert f"not written: {out}/GEAR44.MPF (program {ids['GEAR44']})" in message
    assert f"{out}/GEAR42.MPF (program" not in message


def swap_for_a_link(out: Path, elsewhere: Path) -> None:
    out.rename(out.with_name("moved"))
    elsewhere.mkdir()
    out.symlink_to(elsewhere, target_is_directory=True)


def swap_for_a_folder(out: Path, elsewhere: Path) -> None:
    out.rename(out.with_name("moved"))
    out.mkdir()


@pytest.mark.parametrize("swap", [swap_for_a_link, swap_for_a_folder])
def test_a_folder_swapped_between_the_plan_and_the_files_is_refused(run, tmp_path, after_plan, swap):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    old_files(out)
    after_plan(lambda files: swap(out, elsewhere))
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    assert result.exit_code == 3, result.output
    assert str(out) in result.stderr and "nothing written" in result.stderr
    ids = stored(run.url, 3)
    assert f"programs {ids['GEAR42']}–{ids['GEAR44']} are stored" in result.stderr
    assert everything_in(out) == []   # the link's folder, or the new folder: nothing written into it
    assert {name: (tmp_path / "moved" / f"{name}.MPF").read_bytes() for name in GEARS} == OLD


def test_a_target_that_is_a_link_is_refused_before_storing(read_only_run, tmp_path):
    """A link to a file in --out itself (one leading out of it is refused as outside --out)."""
    out = tmp_path / "out"
    real = out / "OTHER.MPF"
    out.mkdir()
    real.write_bytes(OLD["GEAR42"])
    (out / "GEAR42.MPF").symlink_to(real)
    before = program_count(read_only_run.url)
    result = read_only_run("instantiate", "--gears", "42-43", "--out", out, "--force")
    assert result.exit_code == 1 and "symbolic link" in result.stderr and "nothing stored" in result.stderr
    assert program_count(read_only_run.url) == before
    assert real.read_bytes() == OLD["GEAR42"] and (out / "GEAR42.MPF").is_symlink()
    assert everything_in(out) == ["GEAR42.MPF", "OTHER.MPF"]


def test_a_target_that_became_a_link_after_the_plan_is_not_written_through(run, tmp_path, after_plan):
    out, real = tmp_path / "out", tmp_path / "real.MPF"
    old_files(out)
    real.write_bytes(b"; not the engine's\n")

    def link_it(files):
        (out / "GEAR43.MPF").unlink()
        (out / "GEAR43.MPF").symlink_to(real)
    after_plan(link_it)
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    assert result.exit_code == 3 and "symbolic link" in result.stderr, result.output
    assert real.read_bytes() == b"; not the engine's\n" and (out / "GEAR43.MPF").is_symlink()
    assert [(out / f"{name}.MPF").read_bytes() for name in ("GEAR42", "GEAR44")] == [OLD["GEAR42"], OLD["GEAR44"]]


def test_a_folder_swapped_while_the_files_are_named_is_said(run, tmp_path, after_plan, monkeypatch):
    """Swapped after the first rename: the files still go into the folder opened at the start
    (never through the new path), and the error says the folder moved and that they were written."""
    out = tmp_path / "out"
    old_files(out)

    def swap_at_first_rename(files):
        real = os.replace

        def replace(*args, **kwargs):
            if not (tmp_path / "moved").exists():
                swap_for_a_folder(out, tmp_path / "elsewhere")
            return real(*args, **kwargs)
        monkeypatch.setattr(os, "replace", replace)
    after_plan(swap_at_first_rename)
    result = run("instantiate", "--gears", "42-44", "--out", out, "--force")
    monkeypatch.undo()
    assert result.exit_code == 3, result.output
    assert "moved or swapped" in result.stderr and "and written" in result.stderr
    assert everything_in(out) == []
    for name in GEARS:
        assert (tmp_path / "moved" / f"{name}.MPF").read_bytes() == latest_text(run.url, name)
    assert everything_in(tmp_path / "moved") == ["GEAR42.MPF", "GEAR43.MPF", "GEAR44.MPF"]
