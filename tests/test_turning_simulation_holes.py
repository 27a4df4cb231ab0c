"""The turning simulation's holes an adversary found (issue 26): a tool change in a block that
moves, the bar behind the blank's back end (it runs on into the chuck), a tool offset other than
the job's, a thread lead other than the drawn pitch and a thread pass run on into the shoulder
behind its relief groove. Each edit of a genuine program (the sample shaft: thread pitch 1.5 on
Ø20, Z0…-23, relief groove Z-22…-26, Ø25 shoulder behind; the EMCO drawing on Ø24 stock, its
back end at Z-30) is refused, on both lathe dialects, naming the line."""
from pathlib import Path

import pytest
from helpers.drawings import DXF

from engine.machines.records import load_machine
from engine.programs.remake import instantiate_job
from engine.simulation.turning.run import simulate_turning
from engine.turning.job_params import ProfileOptions
from engine.verifier import LimitError, verify_program
from importers.dxf import import_dxf

SAMPLE = Path(__file__).parent.parent / "seed_templates" / "drawings" / "sample_shaft.dxf"
EMCO = DXF / "emco_lathe_testNegDXF_R14.dxf"
EMCO_OPTIONS = ProfileOptions(rough_depth=1.0, stock_diameter=24.0)
ISO, S840D = "lathe-iso", "lathe-840d"
RAPID, FEED = {ISO: "G00", S840D: "G0"}, {ISO: "G01", S840D: "G1"}


def job(conn, machine: str, drawing: Path = SAMPLE, options: ProfileOptions | None = None):
    job_id = import_dxf(conn, drawing, machine, options or ProfileOptions(), program_name="HOLES").job_id
    lines = instantiate_job(conn, job_id).lines
    params, modules = conn.execute("SELECT params, module_params FROM job WHERE id = %s", (job_id,)).fetchone()
    return lines, params, modules, load_machine(conn, machine)


def refusals(edited: list[str], params, modules, lathe) -> list[str]:
    """The simulation's refusals of an edited program the verifier itself still reads."""
    verify_program(edited, lathe, params["program_name"])
    return [f"{f.line} {f.message}" for f in simulate_turning(edited, params, modules, lathe).refusals]


def tool_lines(lines: list[str]) -> list[int]:
    return [i for i, line in enumerate(lines) if line.startswith("T")]


@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_tool_change_in_a_block_that_moves_is_refused(conn, machine):
    """`G00 X200.000 Z100.000 T0505`: the turret indexes on the way to the change position."""
    lines, params, modules, lathe = job(conn, machine)
    second = tool_lines(lines)[1]
    assert lines[second - 1].startswith(RAPID[machine] + " X")
    edited = [*lines[:second - 1], f"{lines[second - 1]} {lines[second]}", *lines[second + 1:]]
    if machine == ISO:     # the ISO verifier refuses it itself (adversary 27b H16), before the simulation
        with pytest.raises(LimitError, match="a tool change in a block that moves"):
            verify_program(edited, lathe, params["program_name"])
    else:
        found = refusals(edited, params, modules, lathe)
        assert any("a tool change in a block that moves" in f for f in found), found
    assert not simulate_turning(lines, params, modules, lathe).refused


@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_tool_offset_other_than_the_job_s_is_refused(conn, machine):
    """T0109 / T1 D9 where prep:1 says offset 1: every cut lies off by the two offsets' difference."""
    lines, params, modules, lathe = job(conn, machine)
    first = tool_lines(lines)[0]
    tool, offset = modules["prep:1"]["tool"], modules["prep:1"]["tool_offset"]
    wrong = offset % 99 + 1
    assert lines[first] == (f"T{tool:02d}{offset:02d}" if machine == ISO else f"T{tool} D{offset}")
    lines[first] = f"T{tool:02d}{wrong:02d}" if machine == ISO else f"T{tool} D{wrong}"
    found = refusals(lines, params, modules, lathe)
    assert any(f"tool offset {wrong}" in f and f"whose offset is {offset}" in f for f in found), found


def test_an_840d_offset_called_in_a_block_of_its_own_is_checked_too(conn):
    lines, params, modules, lathe = job(conn, S840D)
    first = tool_lines(lines)[0]
    tool = modules["prep:1"]["tool"]
    lines[first:first + 1] = [f"T{tool} D{modules['prep:1']['tool_offset']}", "D9"]
    assert any("tool offset 9" in f for f in refusals(lines, params, modules, lathe))


@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_thread_lead_other_than_the_drawn_pitch_is_refused(conn, machine):
    """Every pass at lead 2.0 on the pitch-1.5 thread: the helix is not the drawing's."""
    lines, params, modules, lathe = job(conn, machine)
    pitch = next(v["thread_pitch"] for v in modules.values() if v.get("kind") == "THREAD")
    written = "F1.5000" if machine == ISO else "K1.5"
    assert pitch == 1.5 and any(written in line for line in lines)
    edited = [line.replace(written, "F2.0000" if machine == ISO else "K2") for line in lines]
    found = refusals(edited, params, modules, lathe)
    assert any("thread lead 2.0000 mm" in f and "pitch 1.5000 mm" in f for f in found), found


@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_thread_pass_run_on_into_the_shoulder_is_refused(conn, machine):
    """The last pass to Z-30 instead of Z-23: past the Z-22…-26 groove, 4 mm into the Ø25 shoulder."""
    lines, params, modules, lathe = job(conn, machine)
    last = max(i for i, line in enumerate(lines) if line.startswith(("G32", "G33")))
    assert "Z-23.000" in lines[last]
    lines[last] = lines[last].replace("Z-23.000", "Z-30.000")
    found = refusals(lines, params, modules, lathe)
    assert any("a cut into the finished part" in f and "Z-30.000" in f for f in found), found


def _before_last_op_leaves(lines: list[str], machine: str, inserted: list[str]) -> list[str]:
    """`inserted` just before the last operation's rapid to X124 (the EMCO job's tool-change X)."""
    leave = max(i for i, line in enumerate(lines) if line.startswith(f"{RAPID[machine]} X124.000 Z-"))
    return [*lines[:leave], *inserted, *lines[leave:]]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_rapid_into_the_bar_behind_the_back_end_is_refused(conn, machine):
    """10 mm behind the part's back end (Z-30) the bar runs on to the chuck at the stock's Ø24."""
    lines, params, modules, lathe = job(conn, machine, EMCO, EMCO_OPTIONS)
    assert params["stock_z_back"] == -30.0 and params["stock_diameter"] == 24.0
    rapid = RAPID[machine]
    edited = _before_last_op_leaves(lines, machine, [f"{rapid} X26.000 Z-40.000", f"{rapid} X4.000 Z-40.000"])
    found = refusals(edited, params, modules, lathe)
    assert any("X4.000 Z-40.000" in f and "a rapid through material" in f for f in found), found


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_cut_behind_the_back_end_is_refused(conn, machine):
    """`G01 X0 Z-40`: a cut behind the stock's back end goes into what holds the part."""
    lines, params, modules, lathe = job(conn, machine, EMCO, EMCO_OPTIONS)
    rapid, feed = RAPID[machine], FEED[machine]
    inserted = [f"{rapid} X26.000 Z-40.000", f"{feed} X0.000 Z-40.000", f"{rapid} X26.000 Z-40.000"]
    found = refusals(_before_last_op_leaves(lines, machine, inserted), params, modules, lathe)
    assert any("X0.000 Z-40.000" in f and "behind the blank's back end" in f for f in found), found


@pytest.mark.parametrize("machine", [ISO, S840D])
def test_a_runner_s_wide_clearance_does_not_widen_the_run_out_behind_the_back_end(conn, machine):
    """Adversary: params.clearance is the runner's to edit; set to 31 mm it let a pass run 30 mm
    into the bar the chuck holds. The run-out behind a stored back end stays the planner's 2 mm."""
    lines, params, modules, lathe = job(conn, machine, EMCO, EMCO_OPTIONS)
    rapid, feed = RAPID[machine], FEED[machine]
    inserted = [f"{rapid} X26.000 Z-40.000", f"{feed} X20.000 Z-40.000", f"{rapid} X26.000 Z-40.000"]
    found = refusals(_before_last_op_leaves(lines, machine, inserted), {**params, "clearance": 31.0}, modules, lathe)
    assert any("X20.000 Z-40.000" in f and "behind the blank's back end" in f for f in found), found
