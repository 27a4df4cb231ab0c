"""The geometry of the programs of every gear class (issue 3), checked against formulas of
docs/reference/hobbing.md computed here from the gear, hob and machine rows read with SQL, and
read with tests/helpers/nc_reader.py (no engine code reads the programs).

Seeded gears: 50 the paper's taper gear (m2 z19 d_a 42.5 δ 6.5° 40Cr grade 7), 51 crowned
(m2.5 z32 b30 C_β 0.02), 53 worm wheel (m3 z40 β 4.05° R), 54 duplex (m2 z30 b20 over a
unit z19 b15 at Z-75), 43 helical R and 44 helical L, 45 spur m4 (two cuts).
"""
from __future__ import annotations

import math

import psycopg
import pytest
from helpers import feed_mark_reference
from helpers.nc_reader import read_program

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode

ROUND = 0.0015   # mm: the program writes 3 decimals; a difference of two rounded values


def gear(conn, gear_id):
    row = conn.execute("SELECT module, teeth, pressure_angle, helix_angle, hand, face_width, tip_diameter, "
                       "root_diameter, cone_angle, crowning FROM gear WHERE id = %s", (gear_id,)).fetchone()
    keys = ("mn", "z2", "alpha", "beta", "hand", "b", "da2", "df2", "cone", "crowning")
    return {k: (float(v) if v is not None and k != "hand" else v) for k, v in zip(keys, row)}


def hob_of(conn, program):
    hob_id = next(line.split()[2] for line in program.lines if line.startswith("; HOB "))
    row = conn.execute("SELECT module, starts, tip_diameter, hand, length FROM hob WHERE id = %s",
                       (hob_id,)).fetchone()
    return dict(zip(("mn", "z0", "da0", "hand", "length"), (float(row[0]), row[1], float(row[2]), row[3],
                                                              float(row[4]))))


def lead_angle(hob):
    """§B1: sin γ = z0·m/(d_a0 − 2.5·m)."""
    return math.degrees(math.asin(hob["z0"] * hob["mn"] / (hob["da0"] - 2.5 * hob["mn"])))


def program_of(conn, gear_id, **choices):
    program = instantiate_gear(conn, gear_id, choices=Choices(**choices))
    return program, read_program(program.text)


def cutting_moves(nc):
    """G1 moves, in order."""
    return nc.moves_in("G1")


# ---------------------------------------------------------------- taper (the paper's gear)

def test_taper_x_follows_z_along_the_cone(conn):
    program, nc = program_of(conn, 50)
    g, hob = gear(conn, 50), hob_of(conn, program)
    slope = math.tan(math.radians(g["cone"]))
    slanted = [m for m in cutting_moves(nc) if {"X", "Z"} <= m.changed]
    assert slanted, "the taper pass must move X and Z together (G1 X… Z…)"
    # a spur gear's hob is swivelled by γ only: its polyline (issue 29) runs along the cone
    for move in slanted:
        dz = move.end["Z"] - move.start["Z"]
        assert abs((move.end["X"] - move.start["X"]) / dz - slope) < 2 * ROUND / abs(dz)
    # each pass crosses both faces: from above Z = 0 to below Z = -b (climb), without a gap
    passes = [[]]
    for move in slanted:
        if passes[-1] and move.start != passes[-1][-1].end:
            passes.append([])
        passes[-1].append(move)
    for moves in passes:
        assert moves[0].start["Z"] > 0 and moves[-1].end["Z"] < -g["b"]
    # at the top face (Z = 0) the last cut reaches the root cone: the hob's tip section (an
    # ellipse r0 × r0/cos η for the swivel η = γ of a spur gear, §B2) touches the root line
    # x = d_f2/2 + z·tan δ, so its centre lies the ellipse's support distance off that line
    # (for δ = 0 this is (d_f2 + d_a0)/2, §B3)
    last = next(m for m in passes[-1] if m.end["Z"] <= 0 <= m.start["Z"])
    x_at_top = last.start["X"] + (0 - last.start["Z"]) * (last.end["X"] - last.start["X"]) / (
        last.end["Z"] - last.start["Z"])
    delta, eta, r0 = math.radians(g["cone"]), math.radians(lead_angle(hob)), hob["da0"] / 2
    support = r0 * math.sqrt(math.cos(delta) ** 2 + (math.sin(delta) / math.cos(eta)) ** 2)
    assert abs(x_at_top - (g["df2"] / 2 + support / math.cos(delta))) < 0.01


def test_taper_feed_along_the_slant_keeps_the_axial_feed(conn):
    program, nc = program_of(conn, 50)
    slanted = [m for m in cutting_moves(nc) if {"X", "Z"} <= m.changed][-1]
    axial = slanted.feed * math.cos(math.radians(gear(conn, 50)["cone"]))
    assert abs(axial - PAPER_AXIAL_BOUNDED) < 0.1   # the paper's case, bounded by its grade's feed marks


# The paper's case (§D): 246 r/min, 105 axial and 36 radial mm/min, i.e. 105/(246/19) = 8.11 mm per
# workpiece rev, 2.7× the roughing maximum 3.0 for m2 (§C): bounded to 3.0 mm/rev, radial scaled alike.
# Its single cut is the last one: at 3.0 mm/rev its feed marks (§B6) would be deeper than grade 7
# allows on m2 z19 b20 (d_a0 70, cone 6.5°), so the axial feed is bounded further, the radial not.
PAPER_FEED_PER_REV = 105.0 / (246 / 19)
PAPER_AXIAL_BOUNDED = round(min(3.0, feed_mark_reference.bound(7, 2, 19, 0, 20, 20, 70, 6.5)) * 246 / 19, 1)
PAPER_RADIAL_BOUNDED = round(36.0 * 3.0 / PAPER_FEED_PER_REV, 1)


def test_the_papers_example_reproduced(conn):
    """m2 z19 40Cr grade 7, 1-start AA hob, rough, no shift, coolant, tailstock (§D): the
    seeded case gives 246 r/min; its feeds are bounded to the §C roughing maximum for m2."""
    program, nc = program_of(conn, 50)
    hob = hob_of(conn, program)
    assert hob["z0"] == 1 and "AA" in next(line for line in program.lines if line.startswith("; HOB "))
    assert nc.block_with("M3").words["S"] == 246
    infeed = next(m for m in cutting_moves(nc) if m.changed == {"X"})
    assert infeed.feed == PAPER_RADIAL_BOUNDED
    assert nc.index("M8") is not None and nc.index("M20") is not None   # coolant on, tailstock clamp
    assert all(m.end["Y"] == 0 for m in nc.moves if "Y" in m.changed)   # no shift: Y at the hob centre
    job = conn.execute("SELECT cutting FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    assert job["hob_speed"] == 246 and job["rough"] == {"axial_feed": PAPER_AXIAL_BOUNDED,
                                                        "radial_feed": PAPER_RADIAL_BOUNDED}
    assert any(f"{PAPER_FEED_PER_REV:.2f}" in note and "bounded to 3.00" in note for note in job["notes"])
    assert job["case_ids"], "the job records which cases its cutting data came from"


# ---------------------------------------------------------------- crowned

def crown_points(nc):
    """(Z, X) of the polyline's vertices: per cut (a run of G1 moves between rapids: infeed,
    the approach to the first vertex, the polyline, the run-out), the approach's end and the
    polyline's vertices."""
    runs, run = [], []
    for move in nc.moves:
        if move.mode == "G1":
            run.append(move)
        elif run:
            runs, run = runs + [run], []
    return [(m.end["Z"], m.end["X"]) for run in runs[-1:] for m in run[1:-1]]


def test_crowning_is_a_symmetric_parabola_deepest_at_the_faces(conn):
    """§B11: the root a(Z) = a_mid − Δa·(2(Z − Z_m)/b)², Δa = C_β/sin α_n. The hob's tip circle
    is tangent to it, so its centre lies r0 along the root's normal: a(Z) + r0·(√(1 + a'²) − 1)
    (a swivel of a few degrees moves it by less than 0.01 mm); the polyline runs beyond each
    face until the contact point, r0·sin(atan a') inside the centre, has passed the face."""
    program, nc = program_of(conn, 51)
    g, hob = gear(conn, 51), hob_of(conn, program)
    points = crown_points(nc)
    assert len(points) - 1 >= 20, "at least 20 segments across the face"
    full_depth, r0 = (g["df2"] + hob["da0"]) / 2, hob["da0"] / 2
    crown = g["crowning"] / math.sin(math.radians(g["alpha"]))
    mid = -g["b"] / 2
    face_slope = 4 * crown / g["b"]
    beyond = r0 * face_slope / math.sqrt(1 + face_slope ** 2)
    assert max(z for z, _ in points) >= beyond - ROUND and min(z for z, _ in points) <= -g["b"] - beyond + ROUND
    by_z = {round(z, 3): x for z, x in points}
    for z, x in points:                                              # symmetric about mid-face
        mirror = round(2 * mid - z, 3)
        assert mirror in by_z and abs(by_z[mirror] - x) < ROUND
        slope = 8 * crown * (z - mid) / g["b"] ** 2
        expected = full_depth - crown * (2 * (z - mid) / g["b"]) ** 2 + r0 * (math.sqrt(1 + slope ** 2) - 1)
        assert abs(x - expected) < 0.01, (z, x, expected)
    assert max(x for _, x in points) == pytest.approx(full_depth, abs=0.01)   # full depth at mid-face
    assert max(x for _, x in points) == by_z[round(mid, 3)]         # largest centre distance mid-face


# ---------------------------------------------------------------- worm wheel

def test_worm_wheel_plunges_radially_without_z(conn):
    program, nc = program_of(conn, 53)
    g, hob = gear(conn, 53), hob_of(conn, program)
    coupled = [m for m in nc.moves if m.block < nc.index("EGOFS")]   # then it leaves for the load position
    z_values = {m.end["Z"] for m in coupled if m.end["Z"] is not None}   # from the load position X first
    assert z_values == {-g["b"] / 2}, "the hob stays in the wheel's mid-plane"
    assert all("Z" not in m.changed for m in coupled if m.start["Z"] is not None)
    plunge = [m for m in cutting_moves(nc) if m.changed == {"X"}]
    assert abs(plunge[-1].end["X"] - (g["df2"] + hob["da0"]) / 2) < 0.01
    # shaft angle 90°: A = h_hob·γ − h_gear·β (§A7), 0 but for the hob's lead differing from the helix (§B10)
    assert hob["hand"] == g["hand"] == "R"
    assert abs(nc.block_with("A").words["A"] - (lead_angle(hob) - g["beta"])) < 0.002
    assert nc.index("G4") is not None and nc.index("G4") > nc.index("move G1")   # dwell at depth
    egon = nc.block_with("EGON").call("EGON")
    assert egon.args[:5] == ("C", "FINE", "B", str(-hob["z0"] if hob["hand"] == "R" else hob["z0"]), "40")
    assert len(egon.args) == 5, "no differential term: no axial pass"


def test_worm_wheel_tangential_feed_along_y_with_the_table_coupled(conn):
    program, nc = program_of(conn, 53, worm_feed="tangential")
    g, hob = gear(conn, 53), hob_of(conn, program)
    full_depth = (g["df2"] + hob["da0"]) / 2
    assert all("Z" not in m.changed for m in nc.moves if m.start["Z"] is not None and m.block < nc.index("EGOFS"))
    tangential = [m for m in cutting_moves(nc) if m.changed == {"Y"}]
    assert len(tangential) == 1
    move = tangential[0]
    assert abs(move.start["X"] - full_depth) < 0.01                   # centre distance fixed first
    assert move.start["Y"] > 0 > move.end["Y"]
    # the whole hob is clear of the wheel at both ends (half-chord at the tip + half the hob)
    chord = math.sqrt((g["da2"] / 2) ** 2 - (full_depth - hob["da0"] / 2) ** 2)
    assert min(move.start["Y"], -move.end["Y"]) >= chord + hob["length"] / 2
    assert nc.block_with("EGDEF").call("EGDEF").args == ("C", "B", "1", "Y", "1")
    egon = nc.block_with("EGON").call("EGON").args
    expected = 360 * math.cos(math.radians(lead_angle(hob))) / (math.pi * g["mn"] * g["z2"])   # §A5
    assert egon[5] == "Y" and abs(float(egon[6]) - expected) < 1e-6 and egon[7] == "1"


# ---------------------------------------------------------------- duplex

def test_duplex_cuts_both_units_with_their_own_parameters(conn):
    program, nc = program_of(conn, 54)
    g, hob = gear(conn, 54), hob_of(conn, program)
    unit = conn.execute("SELECT teeth, face_width, tip_diameter, z_top FROM gear_unit WHERE gear_id = 54"
                        ).fetchone()
    teeth2, b2, da2_2, z_top = unit[0], float(unit[1]), float(unit[2]), float(unit[3])
    couplings = [block.call("EGON").args for block in nc.blocks if block.call("EGON")]
    assert [args[4] for args in couplings] == [str(int(g["z2"])), str(teeth2)]
    passes = [m for m in cutting_moves(nc) if m.changed == {"Z"}]
    assert len(passes) == 2
    first, second = passes
    assert abs(first.start["X"] - (g["df2"] + hob["da0"]) / 2) < 0.01
    assert abs(second.start["X"] - (da2_2 - 4.5 * g["mn"] + hob["da0"]) / 2) < 0.01
    assert first.start["Z"] > 0 and first.end["Z"] < -g["b"]               # across unit 1
    assert first.end["Z"] > z_top                                          # ... and not into unit 2
    assert second.start["Z"] > z_top and second.end["Z"] < z_top - b2       # across unit 2
    # feeds per workpiece revolution are the same; per minute they follow each unit's teeth
    assert abs(second.feed / first.feed - g["z2"] / teeth2) < 0.01
    egon_blocks = [block.index for block in nc.blocks if block.call("EGON")]
    assert egon_blocks[1] > first.block and egon_blocks[1] < second.block


def test_a_unit_written_in_sql_without_its_diameters_gets_them_as_an_import_would(conn):
    """A unit inserted by a DBA without tip and root: spur teeth of the gear's module, tip
    m·(z + 2), root tip − 2·2.25·m (as `engine gears import` computes them). Before, the
    simulation met the missing root as a bug (exit 2) in the middle of a batch."""
    conn.execute("UPDATE gear_unit SET tip_diameter = NULL, root_diameter = NULL WHERE gear_id = 54")
    program, nc = program_of(conn, 54)
    g, hob = gear(conn, 54), hob_of(conn, program)
    teeth2 = conn.execute("SELECT teeth FROM gear_unit WHERE gear_id = 54").fetchone()[0]
    root2 = g["mn"] * (teeth2 + 2) - 2 * 2.25 * g["mn"]
    second = [m for m in cutting_moves(nc) if m.changed == {"Z"}][1]
    assert abs(second.start["X"] - (root2 + hob["da0"]) / 2) < 0.01


def test_duplex_refuses_units_too_close_for_the_hob(conn):
    conn.execute("UPDATE gear_unit SET z_top = -30 WHERE gear_id = 54")
    with pytest.raises(EngineError, match="wider gap"):
        instantiate_gear(conn, 54)


def test_duplex_inherits_spur_rows_and_stores_only_its_own(conn):
    own = conn.execute("SELECT count(*) FROM assembly WHERE gear_class = 'duplex'").fetchone()[0]
    spur = conn.execute("SELECT count(*) FROM assembly WHERE gear_class = 'spur'").fetchone()[0]
    assembled = conn.execute("SELECT count(*), count(*) FILTER (WHERE inherited_from = 'spur') "
                             "FROM template_view WHERE gear_class = 'duplex'").fetchone()
    assert assembled == (own + spur, spur) and own < spur
    conn.execute("""UPDATE template_view SET o = 'f"G0 Z{z_start:.3f} ; SPUR"'
                    WHERE gear_class = 'spur' AND id = 1252""")
    program = instantiate_gear(conn, 54, mode=RunMode(draft=True))
    assert sum(line.endswith("; SPUR") for line in program.lines) == 1, "spur's edit reaches duplex's draft"


# ---------------------------------------------------------------- helical differential, feed modes

@pytest.mark.parametrize("gear_id", [43, 44])
@pytest.mark.parametrize("feed_mode", ["climb", "conventional"])
def test_helical_differential_has_the_hands_sign_in_either_feed_mode(conn, gear_id, feed_mode):
    program, nc = program_of(conn, gear_id, feed_mode=feed_mode)
    g = gear(conn, gear_id)
    size = 360 * math.sin(math.radians(g["beta"])) / (math.pi * g["mn"] * g["z2"])   # §B9
    egon = nc.block_with("EGON").call("EGON").args
    # §A7 on the DIN 66217 hobber: k_Z = −h_gear·size, whatever the feed direction
    assert egon[5] == "Z" and abs(float(egon[6]) - (-size if g["hand"] == "R" else size)) < 1e-6


def test_conventional_enters_below_the_blank_and_feeds_up(conn):
    program, nc = program_of(conn, 42, feed_mode="conventional")
    g, hob = gear(conn, 42), hob_of(conn, program)
    axial = [m for m in cutting_moves(nc) if m.changed == {"Z"}][-1]
    infeed = [m for m in cutting_moves(nc) if m.changed == {"X"}][-1]
    h = (g["da2"] + hob["da0"]) / 2 - infeed.end["X"]
    approach = math.sqrt(h * (hob["da0"] - h))                       # §B7 spur
    assert infeed.end["Z"] <= -g["b"] - approach                       # infeed in air below the blank
    assert axial.end["Z"] > 0 > axial.start["Z"]


def test_conventional_climb_roughs_up_and_finishes_down(conn):
    program, nc = program_of(conn, 45, feed_mode="conventional-climb")
    rough, finish = [m for m in cutting_moves(nc) if m.changed == {"Z"}]
    assert rough.end["Z"] > rough.start["Z"] and finish.end["Z"] < finish.start["Z"]
    assert finish.start["X"] < rough.start["X"]


def test_tailstock_and_coolant_are_rows_switched_by_the_job(conn):
    program, nc = program_of(conn, 42, tailstock=False, coolant=False)
    assert not {"M20", "M21", "M8", "M9"} & set(nc.events)
    program, nc = program_of(conn, 42)
    assert nc.index("M20") < nc.index("motion") and nc.index("M21") > nc.indexes("motion")[-1]


# ---------------------------------------------------------------- shifting

def test_shift_per_part_walks_within_the_usable_hob_length(conn):
    program, nc = program_of(conn, 42, shift_per_part=2.5)
    g, hob = gear(conn, 42), hob_of(conn, program)
    generating = 2 * 2.25 * g["mn"] / math.tan(math.radians(g["alpha"])) + math.pi * g["mn"]   # §B15
    half = (hob["length"] - generating - 2 * 5.0) / 2
    statements = [block.statement for block in nc.blocks if block.statement]
    assert statements[0].startswith("R11=R11+2.500")
    assert statements[1] == f"IF (R11<{-half:.3f}) OR (R11>{half:.3f})"
    assert nc.index("Y=R") is not None and nc.index("Y=R") < nc.index("move G1")
    limits = nc.block_with("G25").words["Y"], nc.block_with("G26").words["Y"]
    assert limits[0] <= -half and limits[1] >= half


def test_a_shift_step_of_whole_axial_pitches_is_refused(conn):
    program = instantiate_gear(conn, 42)
    hob = hob_of(conn, program)
    pitch = math.pi * hob["mn"] / math.cos(math.radians(lead_angle(hob)))
    with pytest.raises(EngineError, match="axial pitch"):
        instantiate_gear(conn, 42, choices=Choices(shift_per_part=round(2 * pitch, 3)))
    with pytest.raises(EngineError, match="no hob has length"):   # the hob is too short for the step
        instantiate_gear(conn, 42, choices=Choices(shift_per_part=80))


# ---------------------------------------------------------------- classification and refusals

def test_classify_explains_the_path(read_only_run):
    out = read_only_run("classify", "--gear", 50).stdout
    assert out.splitlines()[0] == "gear 50: class taper"
    assert "yes (cone_angle = 6.5) → taper" in out and "H-M2-AA-R1" in out
    out = read_only_run("classify", "--gear", 53).stdout
    assert "named class worm_wheel explicitly" in out and "H-WW-M3-R1" in out
    out = read_only_run("classify", "--gear", 54).stdout
    assert "has it further toothed units? yes" in out and "→ duplex" in out


def test_a_gear_no_class_fits_is_refused_with_the_reason(read_only_run, tmp_path):
    path = tmp_path / "gears.csv"
    path.write_text("gear_id,module,teeth,face_width,cone_angle,crowning\n900,2,19,20,6.5,0.02\n")
    result = read_only_run("gears", "import", path)
    assert result.exit_code == 1
    assert "line 2, column gear_class: no class hobs a crowned taper gear" in result.stderr + result.stdout


def test_a_gear_no_hob_fits_is_refused_with_the_property(run, tmp_path):
    path = tmp_path / "gears.csv"
    path.write_text("gear_id,module,teeth,face_width\n901,1.25,40,12\n")
    assert run("gears", "import", path).exit_code == 0
    result = run("instantiate", "--gear", 901)
    assert result.exit_code == 1 and "Traceback" not in result.stderr
    assert "no hob" in result.stderr and "module 1.25" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_suggest_for_the_papers_gear_proposes_its_published_data(read_only_run):
    import json

    out = read_only_run("suggest", "--gear", 50, "--json")
    assert out.exit_code == 0, out.output
    proposal = json.loads(out.stdout)
    text = json.dumps(proposal)
    assert '"hob_speed": 246' in text
    # the suggestion is per cut kind, bounded by §C alone: the feed-mark bound of the last cut is the job's
    assert (proposal["rough"]["axial_feed"], proposal["rough"]["radial_feed"]) == (round(3.0 * 246 / 19, 1),
                                                                                   PAPER_RADIAL_BOUNDED)
    assert any(f"axial feed {PAPER_FEED_PER_REV:.2f} mm per workpiece rev" in note and "bounded to 3.00" in note
               for note in proposal["notes"])


def test_a_confirmed_job_becomes_a_case_of_the_history(run):
    import json

    job_id = json.loads(run("instantiate", "--gear", 45, "--json").stdout)["job_id"]
    before = json.loads(run("cases", "list", "--json").stdout)["cases"]
    confirmed = run("cases", "confirm", "--job", job_id)
    assert confirmed.exit_code == 0, confirmed.output
    new = json.loads(run("cases", "list", "--json").stdout)["cases"][len(before):]
    assert [(case["cut"], case["job_id"]) for case in new] == [("rough", job_id), ("finish", job_id)]
    with psycopg.connect(run.url) as conn:
        cutting = conn.execute("SELECT cutting FROM job WHERE id = %s", (job_id,)).fetchone()[0]
    assert [case["axial_feed"] for case in new] == [cutting["rough"]["axial_feed"], cutting["finish"]["axial_feed"]]
    again = run("cases", "confirm", "--job", job_id)
    assert again.exit_code == 1 and "already confirmed" in again.stderr


def test_a_table_speed_over_the_machine_limit_is_refused_naming_it(conn):
    program, nc = program_of(conn, 42)
    n0, teeth = nc.block_with("M3").words["S"], gear(conn, 42)["z2"]
    conn.execute("UPDATE machine SET table_speed_max = %s WHERE name = 'hobber-840d'", (n0 / teeth - 1,))
    with pytest.raises(EngineError, match=rf"table speed {n0 / teeth:.1f} r/min \(19 teeth\) exceeds "
                                          rf"hobber-840d's {n0 / teeth - 1:g} r/min"):
        instantiate_gear(conn, 42)


def test_the_table_speed_of_every_duplex_unit_is_checked(conn):
    program, nc = program_of(conn, 54)
    n0 = nc.block_with("M3").words["S"]
    unit1, unit2 = gear(conn, 54)["z2"], 19
    between = (n0 / unit1 + n0 / unit2) / 2       # unit 1 (30 teeth) turns slower, unit 2 faster
    conn.execute("UPDATE machine SET table_speed_max = %s WHERE name = 'hobber-840d'", (between,))
    with pytest.raises(EngineError, match=r"\(19 teeth\) exceeds"):
        instantiate_gear(conn, 54)


@pytest.mark.parametrize("face_width", [30, 12, 6])
@pytest.mark.parametrize("feed_mode", ["climb", "conventional-climb"])
def test_the_largest_crowning_is_cut_to_its_root_on_narrow_faces(conn, face_width, feed_mode):
    """C_β 0.2 (the class's maximum) on faces down to 6 mm: instantiate stores only what the
    simulation proves (3-D hob against the crowned root, §B11), so storing is the assertion;
    the polyline runs beyond both faces by r0·sin(atan a') (the contact point passes them)."""
    conn.execute("UPDATE gear SET crowning = 0.2, face_width = %s WHERE id = 51", (face_width,))
    program, nc = program_of(conn, 51, cuts=2, feed_mode=feed_mode)
    hob = hob_of(conn, program)
    slope = 4 * (0.2 / math.sin(math.radians(20))) / face_width
    beyond = hob["da0"] / 2 * slope / math.sqrt(1 + slope ** 2)
    zs = [z for z, _ in crown_points(nc)]
    assert max(zs) >= beyond - ROUND and min(zs) <= -face_width - beyond + ROUND


def test_a_crowning_too_steep_for_its_face_is_refused_in_one_line(conn):
    conn.execute("UPDATE gear SET crowning = 0.2, face_width = 4 WHERE id = 51")
    with pytest.raises(EngineError, match=r"^gear 51: crowning 0.2 mm on a face of 4 mm slopes the root by 30°"):
        program_of(conn, 51)
