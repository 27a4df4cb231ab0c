"""Worm wheels cut with catalogue worm-wheel hobs (issue 29). Worm-gear drawings and hob catalogues
give the worm's axial module m_x (DIN 3975); the hob record says so (module_kind axial) and the
engine matches it to the wheel's axial module. Every program here is made by `instantiate_gear`,
which stores only what the verifier and the hobbing simulation prove.

Expected numbers come from the reference (docs/reference/hobbing.md §B1, §B10), computed here:
* the hob's lead angle γ0 from tan γ0 = z0·m_x/d_m0, d_m0 = d_a0 − 2.5·m_x·cos γ0, solved by
  bisection (the engine iterates; the two must agree);
* the tangential coupling k_Y = 360/(π·m_x·z2) degrees of C per mm of Y, for either hand (§A7);
* the radial plunge to the full-depth centre distance (d_f2 + d_a0)/2, the swivel h·(γ0 − γ).

The wheels: m_x 3, z2 40, worm diameter quotient q = 10 (d1 = 30 mm), so the wheel's helix is the
worm's lead, tan γ = z1/q: 5.711° for one start, 11.310° for two; tip 126 and root 112.5 mm
(d2 = m_x·z2 = 120, addendum m_x, dedendum 1.25·m_x). The hobs copy the worm: d_a0 = 37.5 mm."""
from __future__ import annotations

import math

import psycopg
import pytest
from helpers.nc_reader import read_program

from engine.errors import EngineError
from engine.gears.hob_geometry import hob_axial_module, lead_angle, normal_from_axial
from engine.gears.hob_library import import_hobs
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

M_X, Z2, Q, HOB_TIP = 3.0, 40, 10.0, 37.5
TIP, ROOT = M_X * Z2 + 2 * M_X, M_X * Z2 - 2.5 * M_X
HOBS = """id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class,purpose,module_kind
CAT-WW-MX3-R1,3,20,1,37.5,90,R,A,worm_wheel,axial
CAT-WW-MX3-L1,3,20,1,37.5,90,L,A,worm_wheel,axial
CAT-WW-MX3-R2,3,20,2,37.5,90,R,A,worm_wheel,axial
CAT-WW-MX3-L2,3,20,2,37.5,90,L,A,worm_wheel,axial
"""
WHEELS = {(hand, starts): 900 + 10 * starts + (hand == "L") for hand in "RL" for starts in (1, 2)}


def worm_lead(starts: int) -> float:
    return math.degrees(math.atan(starts / Q))


def hob_lead(starts: int) -> float:
    """γ0 of the catalogue hob (§B1, §B10): the root of tan γ = z0·m_x/(d_a0 − 2.5·m_x·cos γ), by bisection."""
    low, high = 0.0, math.pi / 4
    for _ in range(100):
        middle = (low + high) / 2
        if math.tan(middle) * (HOB_TIP - 2.5 * M_X * math.cos(middle)) < starts * M_X:
            low = middle
        else:
            high = middle
    return math.degrees((low + high) / 2)


@pytest.fixture
def wheels(conn, tmp_path):
    path = tmp_path / "catalogue.csv"
    path.write_text(HOBS, encoding="utf-8")
    import_hobs(conn, path)
    for (hand, starts), gear_id in WHEELS.items():
        conn.execute("INSERT INTO gear (id, gear_class, module, module_kind, teeth, helix_angle, hand, face_width, "
                     "tip_diameter, root_diameter, material, hardness, quality_grade, quantity) "
                     "VALUES (%s, 'worm_wheel', %s, 'axial', %s, %s, %s, 25, %s, %s, 'CuSn12', 90, 8, 20)",
                     (gear_id, M_X, Z2, round(worm_lead(starts), 6), hand, TIP, ROOT))
    return conn


def made(conn, gear_id: int, feed: str):
    program = instantiate_gear(conn, gear_id, choices=Choices(worm_feed=feed))
    hob = next(line.split()[2] for line in program.lines if line.startswith("; HOB "))
    return hob, read_program(program.text)


def test_the_conversion_gives_the_catalogue_module_and_lead_back():
    for starts in (1, 2, 3):
        normal = normal_from_axial(M_X, starts, HOB_TIP)
        assert normal == pytest.approx(M_X * math.cos(math.radians(hob_lead(starts))), abs=1e-12)
        assert lead_angle(normal, starts, HOB_TIP) == pytest.approx(hob_lead(starts), abs=1e-9)
        assert hob_axial_module(normal, starts, HOB_TIP) == pytest.approx(M_X, abs=1e-12)


@pytest.mark.parametrize("hand", ["R", "L"])
@pytest.mark.parametrize("starts", [1, 2])
def test_a_catalogue_hob_feeds_tangentially_with_the_worms_pitch(wheels, hand, starts):
    hob, nc = made(wheels, WHEELS[hand, starts], "tangential")
    assert hob == f"CAT-WW-MX3-{hand}{starts}"
    egon = nc.block_with("EGON").call("EGON").args
    k_y = 360 / (math.pi * M_X * Z2)        # §B10, degrees of C per mm of Y, either hand (§A7)
    assert egon[5] == "Y" and float(egon[6]) == pytest.approx(k_y, abs=1e-6), egon
    assert egon[3] == str(-starts if hand == "R" else starts) and egon[4] == str(Z2)   # B:C = z0:z2, hob's hand


@pytest.mark.parametrize("hand", ["R", "L"])
@pytest.mark.parametrize("starts", [1, 2])
def test_a_catalogue_hob_plunges_radially_to_the_full_depth(wheels, hand, starts):
    hob, nc = made(wheels, WHEELS[hand, starts], "radial")
    assert hob == f"CAT-WW-MX3-{hand}{starts}"
    plunge = [move for move in nc.moves_in("G1") if move.changed == {"X"}]
    assert plunge[-1].end["X"] == pytest.approx((ROOT + HOB_TIP) / 2, abs=0.001)
    sign = 1 if hand == "R" else -1          # §A7: A = h_hob·γ0 − h_gear·γ, the same hand
    assert nc.block_with("A").words["A"] == pytest.approx(sign * (hob_lead(starts) - worm_lead(starts)), abs=0.001)
    assert len(nc.block_with("EGON").call("EGON").args) == 5, "a radial plunge couples no Y"


def test_a_catalogue_hob_entered_as_normal_does_not_fit_the_wheel(wheels):
    """The old reading of a catalogue hob: its m_x 3 taken as a normal module. Its axial pitch would
    then be π·3/cos γ0, not the wheel's π·3: refused, naming the axial module the wheel needs."""
    wheels.execute("DELETE FROM hob WHERE id LIKE 'CAT-WW-MX3-%'")
    wheels.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, purpose, "
                   "module_kind) VALUES ('CAT-AS-NORMAL', 3, 1, 37.5, 90, 'R', 'A', 'worm_wheel', 'normal')")
    with pytest.raises(EngineError, match=r"no hob has axial module 3 among"):
        instantiate_gear(wheels, WHEELS["R", 1], choices=Choices(worm_feed="tangential"))


def test_a_tangential_wheel_over_module_3_is_cut_once_and_says_so(wheels):
    """A tangential pass feeds the hob through the wheel at full depth once (§B10). The header said
    the module's two cuts (m_x 4 > 3) and the simulation, following one, refused every such wheel;
    two cuts asked for are refused in one line."""
    wheels.execute("UPDATE gear SET module = 4, tip_diameter = 4 * 42, root_diameter = 4 * 37.5 WHERE id = %s",
                   (WHEELS["R", 1],))
    wheels.execute("UPDATE hob SET module = 4, tip_diameter = 50 WHERE id = 'CAT-WW-MX3-R1'")
    wheels.execute("UPDATE machine SET y_min = -150, y_max = 150 WHERE name = 'hobber-840d'")   # the stroke
    _, nc = made(wheels, WHEELS["R", 1], "tangential")
    header = next(line for line in nc.lines if line.startswith("; n0="))
    assert " cuts=1 " in header
    assert len([move for move in nc.moves_in("G1") if move.changed == {"Y"}]) == 1
    with pytest.raises(EngineError, match="two cuts with a tangential feed"):
        instantiate_gear(wheels, WHEELS["R", 1], choices=Choices(worm_feed="tangential", cuts=2))


# ------------------------------------------------------------------ the header's feed word

def test_a_worm_wheels_header_names_its_worm_feed_and_a_feed_mode_given_is_refused(run):
    """New-user review 29: `--feed-mode climb|conventional` on a worm wheel changed only the header's
    word (both fed Y alike), and the default header said `climb` over a RADIAL cut. A worm wheel
    has no axial pass: the header names its worm feed, and a feed mode given is refused."""
    made = {}
    for feed in ("radial", "tangential"):
        result = run("instantiate", "--gear", 53, "--worm-feed", feed)
        assert result.exit_code == 0, result.output
        made[feed] = result.stdout
        n0_line = next(line for line in result.stdout.splitlines() if line.startswith("; n0="))
        assert n0_line.endswith(f" {feed}"), n0_line
        words = [line.split()[-1] for line in result.stdout.splitlines() if line.startswith("; CUT ")]
        assert words and set(words) == {feed.upper()}, words
    with psycopg.connect(run.url) as conn:
        before = conn.execute("SELECT count(*) FROM program").fetchone()[0]
        job = conn.execute("SELECT id FROM job WHERE gear_id = 53 ORDER BY id DESC LIMIT 1").fetchone()[0]
    refused = run("instantiate", "--gear", 53, "--feed-mode", "climb")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1, refused.output
    assert "no axial pass" in refused.stderr and "--feed-mode" in refused.stderr
    again = run("instantiate", "--job", job)   # the stored tangential job, made again
    assert again.exit_code == 0, again.output
    assert program_lines(again.stdout) == program_lines(made["tangential"])
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == before + 1


def program_lines(text: str) -> list[str]:
    """The program up to M30 without its lineage line (which names the program's own id)."""
    lines = text.splitlines()
    return [line for line in lines[:lines.index("M30") + 1] if not line.startswith("; PROGRAM ")]


def test_a_worm_wheel_job_stored_saying_climb_is_made_again_saying_its_worm_feed(run):
    """A job stored before the header named the worm feed (`params.feed_mode` climb) is made again
    with the word its cuts are, and the simulation, which holds the word to the cuts, proves it."""
    assert run("instantiate", "--gear", 53).exit_code == 0
    with psycopg.connect(run.url) as conn:
        job = conn.execute("SELECT id FROM job WHERE gear_id = 53 ORDER BY id DESC LIMIT 1").fetchone()[0]
        conn.execute("UPDATE job SET params = jsonb_set(params, '{feed_mode}', '\"climb\"') WHERE id = %s", (job,))
    again = run("instantiate", "--job", job)
    assert again.exit_code == 0, again.output
    n0_line = next(line for line in again.stdout.splitlines() if line.startswith("; n0="))
    assert n0_line.endswith(" radial"), n0_line


@pytest.mark.parametrize("stated", ["climb", "tangential", "conventional-climb"])
def test_a_worm_wheel_header_misstating_its_feed_is_refused_by_the_simulation(conn, stated):
    from engine.gears.records import load_gear, load_hobs
    from engine.machines.records import load_machine
    from engine.simulation import simulate_program

    lines = instantiate_gear(conn, 53).lines
    forged = [line.replace(" radial", f" {stated}") if line.startswith("; n0=") else line for line in lines]
    hob = next(hob for hob in load_hobs(conn) if f"; HOB {hob.id} " in "\n".join(lines))
    proved = [simulate_program(text, load_gear(conn, 53), hob, load_machine(conn, "hobber-840d"), "GEAR53")
              for text in (lines, forged)]
    assert proved[0].refusals == []
    assert any(f"the header states feed {stated}" in finding.message for finding in proved[1].refusals)
