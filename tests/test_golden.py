"""Every seeded gear under every set of job choices, on the 840D and on the Fanuc hobber (issue 30),
and every golden turning job, instantiates to the bytes of its golden file
(tests/helpers/golden_cases.py says how the files were made and why)."""
import pytest
from helpers.golden_cases import (
    FANUC_MACHINE,
    fanuc_hobbing_file,
    hobbing_cases,
    hobbing_file,
    hobbing_text,
    turning_cases,
    turning_file,
    turning_text,
    without_iso_program_number,
)


def test_every_case_has_its_golden_file_and_no_file_is_left_over():
    expected = ({hobbing_file(*case) for case in hobbing_cases()}
                | {fanuc_hobbing_file(*case) for case in hobbing_cases()}
                | {turning_file(*case) for case in turning_cases()})
    folders = (hobbing_file(42, "default").parent, fanuc_hobbing_file(42, "default").parent,
               turning_file("x", "y").parent)
    present = {path for folder in folders for path in folder.glob("*")}
    assert sorted(map(str, expected - present)) == [] and sorted(map(str, present - expected)) == []


def test_the_golden_files_hold_programs_not_only_refusals():
    texts = [hobbing_file(*case).read_text() for case in hobbing_cases()]
    programs = [text for text in texts if text.startswith("%_N_")]
    assert len(programs) >= 0.7 * len(texts) and all(text.endswith("M30\n") for text in programs)


@pytest.mark.parametrize("gear_id,choice_set", hobbing_cases())
def test_hobbing_program_is_its_golden_file(conn, gear_id, choice_set):
    assert hobbing_text(conn, gear_id, choice_set) == hobbing_file(gear_id, choice_set).read_text()


@pytest.mark.parametrize("gear_id,choice_set", hobbing_cases())
def test_fanuc_hobbing_program_is_its_golden_file(conn, gear_id, choice_set):
    assert hobbing_text(conn, gear_id, choice_set, FANUC_MACHINE) == fanuc_hobbing_file(gear_id, choice_set).read_text()


@pytest.mark.parametrize("name,lathe", turning_cases())
def test_turning_program_is_its_golden_file(conn, tmp_path, name, lathe):
    made, golden = turning_text(conn, tmp_path, name, lathe), turning_file(name, lathe).read_text()
    assert without_iso_program_number(made) == without_iso_program_number(golden)
