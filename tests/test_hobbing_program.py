"""The hobbing program conventions of design notes §7 (Contract) on the seeded gears.

Every expected number is computed here, independently of the engine, from the formulas
of the reference (docs/reference/hobbing.md §A5, §B) and the data in the gear, hob and
machine tables (read with SQL). The programs are read with tests/helpers/nc_reader.py, which
shares no code with engine.verifier.

Seeded gears: 42 spur m2 z19 (one cut), 45 spur m4 z25 (rough + finish), 43 helical R
m3 z41 β15, 44 helical L m2 z30 β15.
"""
from __future__ import annotations

import math
import re

import pytest
from helpers.nc_reader import Block, Move, Program, read_program

from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

SPUR = [42, 45]
HELICAL = [43, 44]
GEARS = SPUR + HELICAL
MACHINE = "hobber-840d"

ANGLE_TOLERANCE = 0.001       # degrees, |A| against η
DIAMETER_TOLERANCE = 0.01     # mm, last cut against (d_f2 + d_a0)/2 (Contract)


# ---------------------------------------------------------------- data, read with SQL

def gear_row(conn, gear_id: int) -> dict:
    row = conn.execute(
        "SELECT id, gear_class, module, teeth, helix_angle, hand, face_width, tip_diameter, "
        "root_diameter FROM gear WHERE id = %s", (gear_id,)).fetchone()
    assert row is not None, f"gear {gear_id} is not seeded"
    keys = ("id", "gear_class", "mn", "z2", "beta", "hand", "b", "da2", "df2")
    gear = dict(zip(keys, row))
    for key in ("mn", "beta", "b", "da2", "df2"):
        gear[key] = float(gear[key])
    return gear


def hob_row(conn, hob_id: str) -> dict:
    row = conn.execute("SELECT id, module, starts, tip_diameter, hand FROM hob WHERE id = %s",
                       (hob_id,)).fetchone()
    assert row is not None, f"hob {hob_id!r} named in the program header is not in the hob table"
    return {"id": row[0], "mn": float(row[1]), "z0": row[2], "da0": float(row[3]), "hand": row[4]}


def machine_row(conn, name: str = MACHINE) -> dict:
    row = conn.execute("SELECT x_min, x_max, y_min, y_max, z_min, z_max, spindle_max "
                       "FROM machine WHERE name = %s", (name,)).fetchone()
    assert row is not None
    keys = ("x_min", "x_max", "y_min", "y_max", "z_min", "z_max", "spindle_max")
    return {k: float(v) for k, v in zip(keys, row)}


# ---------------------------------------------------------------- the program under test

HEADER_HOB = re.compile(r"^; HOB (\S+) z0=(\d+) da0=(\S+) hand=([LR])$")
HEADER_GEAR = re.compile(r"^; GEAR (\d+) CLASS (\S+) m=(\S+) z=(\d+) beta=(\S+)$")


class Case:
    """One gear's program, read, with the gear and the hob it names."""

    def __init__(self, conn, gear_id: int, choices: Choices = Choices()):
        self.program = instantiate_gear(conn, gear_id, choices=choices)
        self.lines = self.program.text.splitlines()
        self.nc: Program = read_program(self.program.text)
        self.gear = gear_row(conn, gear_id)
        self.machine = machine_row(conn)
        hob_lines = [HEADER_HOB.match(line) for line in self.lines if line.startswith("; HOB ")]
        assert len(hob_lines) == 1 and hob_lines[0], f"no readable '; HOB' header line in:\n{self.program.text}"
        self.header_hob = hob_lines[0]
        self.hob = hob_row(conn, hob_lines[0].group(1))

    @property
    def helical(self) -> bool:
        return self.gear["beta"] != 0

    # -- expected values, from the reference formulas

    def lead_angle(self) -> float:
        """§B1: sin γ = z0·mn / d_m0, d_m0 ≈ d_a0 − 2·1.25·mn (degrees)."""
        mn = self.gear["mn"]
        return math.degrees(math.asin(self.hob["z0"] * mn / (self.hob["da0"] - 2.5 * mn)))

    def swivel(self) -> float:
        """§B2: η = γ (spur), β − γ (same hand), β + γ (opposite hands), degrees."""
        gamma = self.lead_angle()
        if not self.helical:
            return gamma
        if self.hob["hand"] == self.gear["hand"]:
            return self.gear["beta"] - gamma
        return self.gear["beta"] + gamma

    def differential(self) -> float:
        """§A7/§B9: k_Z = −h_gear·360·sin β/(π·mn·z2) degrees of C per mm of Z on a DIN 66217
        machine (the seeded hobber): negative for a right-hand gear, positive for a left-hand one."""
        beta = math.radians(self.gear["beta"])
        size = 360 * math.sin(beta) / (math.pi * self.gear["mn"] * self.gear["z2"])
        return -size if self.gear["hand"] == "R" else size

    def tip_contact_distance(self) -> float:
        """Centre distance at which the hob tip touches the gear tip: (d_a2 + d_a0)/2."""
        return (self.gear["da2"] + self.hob["da0"]) / 2

    def full_depth(self) -> float:
        """§B3: a = (d_f2 + d_a0)/2."""
        return (self.gear["df2"] + self.hob["da0"]) / 2

    def approach_needed(self, cut_x: float) -> float:
        """§B7 with h the depth of this cut: spur √(h(d_a0 − h)); helical the upper bound
        √(h(d_a0 − h))/cos η + tan η·√(h(d_a2 − h))."""
        h = self.tip_contact_distance() - cut_x
        da0, da2 = self.hob["da0"], self.gear["da2"]
        spur = math.sqrt(h * (da0 - h))
        if not self.helical:
            return spur
        eta = math.radians(self.swivel())
        return spur / math.cos(eta) + math.tan(eta) * math.sqrt(h * (da2 - h))

    # -- what the program does

    def block(self, i: int) -> Block:
        return self.nc.blocks[i]

    def first(self, event: str) -> int:
        i = self.nc.index(event)
        assert i is not None, f"gear {self.gear['id']}: no {event} in the program:\n{self.program.text}"
        return i

    def feed_moves(self) -> list[Move]:
        return self.nc.moves_in("G1")

    def cuts(self) -> list[dict]:
        """Each cut as its five moves: G0 Z approach → G0 X to just outside the cut (the infeed
        is in air) → G1 X infeed → G1 Z pass → G0 X retract."""
        moves = self.nc.moves
        found = []
        covered = set()
        for k, move in enumerate(moves):
            if move.mode != "G1" or k in covered:
                continue
            text = self.block(move.block).text
            assert set(self.block(move.block).axes) == {"X"}, \
                f"gear {self.gear['id']}: first G1 of a cut must be the X infeed alone, got {text!r}"
            assert 2 <= k and k + 2 < len(moves), f"gear {self.gear['id']}: incomplete cut around {text!r}"
            approach, air, infeed, cross, retract = moves[k - 2], moves[k - 1], move, moves[k + 1], moves[k + 2]
            a_block, air_block, p_block, r_block = (self.block(m.block) for m in (approach, air, cross, retract))
            assert approach.mode == "G0" and set(a_block.axes) == {"Z"}, \
                f"gear {self.gear['id']}: infeed {text!r} not preceded by a G0 Z approach but {a_block.text!r}"
            assert air.mode == "G0" and set(air_block.axes) == {"X"} and air.end["X"] > move.end["X"], \
                f"gear {self.gear['id']}: infeed {text!r} not preceded by a G0 X outside the cut but {air_block.text!r}"
            assert cross.mode == "G1" and "Z" in p_block.axes and set(p_block.axes) <= {"X", "Z"}, \
                f"gear {self.gear['id']}: infeed {text!r} not followed by a G1 Z pass but {p_block.text!r}"
            assert retract.mode == "G0" and set(r_block.axes) == {"X"}, \
                f"gear {self.gear['id']}: pass {p_block.text!r} not followed by a G0 X retract but {r_block.text!r}"
            covered.update({k, k + 1})
            found.append({"approach": approach, "infeed": infeed, "pass": cross, "retract": retract,
                          "x": infeed.end["X"]})
        return found


@pytest.fixture
def case(conn):
    return lambda gear_id, **choices: Case(conn, gear_id, Choices(**choices))


# ---------------------------------------------------------------- header and end

@pytest.mark.parametrize("gear_id", GEARS)
def test_header_names_gear_hob_machine_template_and_program_ends_with_m30(conn, case, gear_id):
    c = case(gear_id)
    g = c.gear
    assert c.lines[0] == f"%_N_GEAR{gear_id}_MPF"
    assert c.lines[1] == ";$PATH=/_N_MPF_DIR"
    assert c.lines[-1].strip() == "M30"

    first_block_line = c.nc.blocks[0].line_no
    header = [line for line in c.lines[2:first_block_line] if line.startswith(";")]
    kinds = [line.split()[1] for line in header if len(line.split()) > 1]
    for kind in ("GEAR", "HOB", "MACHINE", "TEMPLATE"):
        assert kinds.count(kind) == 1, f"header before the first block lacks '; {kind}': {header}"
    assert [k for k in kinds if k in ("GEAR", "HOB", "MACHINE", "TEMPLATE")] == \
        ["GEAR", "HOB", "MACHINE", "TEMPLATE"]

    gear_line = next(line for line in header if line.startswith("; GEAR "))
    match = HEADER_GEAR.match(gear_line)
    assert match, gear_line
    assert int(match[1]) == gear_id
    assert match[2] == g["gear_class"]
    assert float(match[3]) == pytest.approx(g["mn"])
    assert int(match[4]) == g["z2"]
    assert float(match[5]) == pytest.approx(g["beta"])

    hob = c.hob
    assert int(c.header_hob[2]) == hob["z0"]
    assert float(c.header_hob[3]) == pytest.approx(hob["da0"])
    assert c.header_hob[4] == hob["hand"]
    assert hob["mn"] == pytest.approx(g["mn"]), "the hob's module must be the gear's normal module"

    assert f"; MACHINE {MACHINE}" in header
    version = conn.execute("SELECT template_version FROM gear_class WHERE name = %s",
                           (g["gear_class"],)).fetchone()[0]
    assert f"; TEMPLATE {g['gear_class']} v{version}" in header


# ---------------------------------------------------------------- working area

def _limit_block(c: Case, g: int) -> Block:
    blocks = [b for b in c.nc.blocks if g in b.g]
    assert len(blocks) == 1, f"gear {c.gear['id']}: expected one G{g} block, got {[b.text for b in blocks]}"
    block = blocks[0]
    assert block.g == [g] and set(block.axes) == {"X", "Y", "Z"}, \
        f"G{g} must be its own block with X, Y and Z: {block.text!r}"
    assert not block.m and not block.calls and not block.keywords and "F" not in block.words \
        and "S" not in block.words, f"G{g} must be in its own block: {block.text!r}"
    return block


@pytest.mark.parametrize("gear_id", GEARS)
def test_working_area_set_before_first_motion_and_every_move_inside(case, gear_id):
    c = case(gear_id)
    lower, upper = _limit_block(c, 25), _limit_block(c, 26)
    first_motion = c.first("motion")
    assert lower.index < first_motion and upper.index < first_motion
    assert c.first("WALIMON") < first_motion
    for axis in "XYZ":
        assert lower.axes[axis] < upper.axes[axis], f"G25 {axis} not below G26 {axis}"

    programmed = 0
    for move in c.nc.moves:
        block = c.block(move.block)
        for axis, value in block.axes.items():
            if axis in "XYZ":
                programmed += 1
                assert lower.axes[axis] <= value <= upper.axes[axis], \
                    (f"gear {gear_id}: {block.text!r}: {axis}{value} outside "
                     f"G25 {axis}{lower.axes[axis]} … G26 {axis}{upper.axes[axis]}")
    assert programmed > 0


@pytest.mark.parametrize("gear_id", GEARS)
def test_every_move_within_machine_travel(case, gear_id):
    c = case(gear_id)
    m = c.machine
    for move in c.nc.moves:
        block = c.block(move.block)
        for axis, value in block.axes.items():
            if axis in "XYZ":
                low, high = m[f"{axis.lower()}_min"], m[f"{axis.lower()}_max"]
                assert low <= value <= high, \
                    f"gear {gear_id}: {block.text!r}: {axis}{value} outside the machine travel {low} … {high}"


def test_hob_shift_stays_inside_working_area_and_travel(case):
    c = case(42, shift_y=5.0)
    lower, upper = _limit_block(c, 25), _limit_block(c, 26)
    y_moves = [m for m in c.nc.moves if "Y" in c.block(m.block).axes]
    assert y_moves, f"shift_y=5 programs no Y:\n{c.program.text}"
    assert any(m.end["Y"] == pytest.approx(5.0) for m in y_moves)
    for move in y_moves:
        y = c.block(move.block).axes["Y"]
        assert lower.axes["Y"] <= y <= upper.axes["Y"], f"Y{y} outside G25/G26 Y"
        assert c.machine["y_min"] <= y <= c.machine["y_max"]
    assert y_moves[0].block < c.first("move G1"), "the shift comes before cutting"


# ---------------------------------------------------------------- swivel and coupling

@pytest.mark.parametrize("gear_id", GEARS)
def test_swivel_before_coupling_equals_setting_angle(case, gear_id):
    c = case(gear_id)
    a_blocks = c.nc.indexes("A")
    assert a_blocks, f"gear {gear_id}: no swivel A in the program"
    swivel = c.block(a_blocks[0])
    assert re.search(r"\bA=", swivel.text), f"swivel must be written A=…: {swivel.text!r}"
    assert swivel.index < c.first("EGDEF") and swivel.index < c.first("EGON")
    eta = c.swivel()
    assert abs(abs(swivel.axes["A"]) - eta) <= ANGLE_TOLERANCE, \
        (f"gear {gear_id} (hob {c.hob['id']}): |A| = {abs(swivel.axes['A'])}, expected η = {eta:.4f}° "
         f"(γ = {c.lead_angle():.4f}°, β = {c.gear['beta']})")


@pytest.mark.parametrize("gear_id", GEARS)
def test_electronic_gearbox_couples_table_to_hob(case, gear_id):
    c = case(gear_id)
    egdef, egon = c.first("EGDEF"), c.first("EGON")
    assert egdef < egon < c.first("move G1"), "EGDEF, then EGON, before cutting"
    define = c.block(egdef).call("EGDEF")
    assert define.args[:3] == ("C", "B", "1"), str(define)

    on = c.block(egon).call("EGON")
    args = on.args
    assert args[:3] == ("C", "FINE", "B"), str(on)
    assert re.fullmatch(r"[+-]?\d+", args[3]) and re.fullmatch(r"\d+", args[4]), \
        f"generating ratio must be integers: {on}"
    assert abs(int(args[3])) == c.hob["z0"], f"{on}: numerator must be ±z0 = ±{c.hob['z0']}"
    assert int(args[4]) == c.gear["z2"], f"{on}: denominator must be z2 = {c.gear['z2']}"

    if c.helical:
        assert define.args[3:] == ("Z", "1"), f"{define}: Z must be a leading axis of the helical coupling"
        assert len(args) == 8 and args[5] == "Z" and args[7] == "1", f"{on}: expected Z,<factor>,1"
        assert re.fullmatch(r"-?\d+\.\d{6}", args[6]), f"{on}: factor must have 6 decimals"
        expected = c.differential()
        assert abs(float(args[6]) - expected) <= 5e-7 + 1e-12, \
            f"gear {gear_id} hand {c.gear['hand']}: factor {args[6]}, expected {expected:.6f}"
    else:
        assert len(define.args) == 3, f"{define}: spur gear needs no Z leading axis"
        assert len(args) == 5, f"{on}: spur gear needs no differential"


def test_generating_ratio_sign_follows_hob_hand(case):
    """The sign of ±z0 depends on the hob hand (§A5): gear 44 is cut with a left-hand hob,
    the others with right-hand ones."""
    signs = {}
    for gear_id in GEARS:
        c = case(gear_id)
        numerator = float(c.block(c.first("EGON")).call("EGON").args[3])
        signs.setdefault(c.hob["hand"], set()).add(numerator > 0)
    assert set(signs) == {"L", "R"}, "the seed should use hobs of both hands"
    assert len(signs["L"]) == 1 and len(signs["R"]) == 1 and signs["L"] != signs["R"], signs


# ---------------------------------------------------------------- spindle, coolant, feed

@pytest.mark.parametrize("gear_id", GEARS)
def test_spindle_and_coolant_around_the_cuts(case, gear_id):
    c = case(gear_id)
    first_g1 = c.first("move G1")
    last_retract = c.cuts()[-1]["retract"].block
    last_g1 = c.nc.indexes("move G1")[-1]

    m3 = c.block(c.first("M3"))
    assert "S" in m3.words, f"M3 without S: {m3.text!r}"
    n0 = m3.words["S"]
    assert 0 < n0 <= c.machine["spindle_max"], f"gear {gear_id}: S{n0} above {c.machine['spindle_max']}"
    assert m3.index < first_g1
    assert c.first("M8") < first_g1

    m9, egofs, egdel, m5 = c.first("M9"), c.first("EGOFS"), c.first("EGDEL"), c.first("M5")
    assert last_g1 < m9 < egofs < egdel < m5, (last_g1, m9, egofs, egdel, m5)
    assert last_retract < m9, "stop only after the hob is retracted from the last cut"
    assert c.block(egofs).call("EGOFS").args == ("C",) and c.block(egdel).call("EGDEL").args == ("C",)


@pytest.mark.parametrize("gear_id", GEARS)
def test_no_coolant_means_no_m8_and_no_m9(case, gear_id):
    c = case(gear_id, coolant=False)
    assert c.nc.index("M8") is None and c.nc.index("M9") is None, c.program.text
    last_g1 = c.nc.indexes("move G1")[-1]
    assert c.first("M3") < c.first("move G1")
    assert last_g1 < c.first("EGOFS") < c.first("M5")


@pytest.mark.parametrize("gear_id", GEARS)
def test_feed_per_minute_and_cut_structure(case, gear_id):
    c = case(gear_id)
    first_g1 = c.first("move G1")
    g94 = c.first("G94")
    assert g94 < first_g1
    for other in ("G93", "G95"):
        assert all(i < g94 or i > c.nc.indexes("move G1")[-1] for i in c.nc.indexes(other)), \
            f"{other} switches the feed type while cutting"
    for move in c.feed_moves():
        assert move.feed is not None and move.feed > 0, f"G1 without feed: {c.block(move.block).text!r}"
    cuts = c.cuts()    # asserts G0 Z → G1 X → G1 Z → G0 X for every cut
    assert cuts
    assert sum(2 for _ in cuts) == len(c.feed_moves()), "every G1 belongs to a cut"


# ---------------------------------------------------------------- geometry of the cuts

@pytest.mark.parametrize("gear_id", GEARS)
def test_infeed_clear_of_blank_and_pass_beyond_far_face(case, gear_id):
    c = case(gear_id)
    for cut in c.cuts():
        z = cut["infeed"].start["Z"]
        assert z is not None, "infeed before any Z is known"
        needed = c.approach_needed(cut["x"])
        h = c.tip_contact_distance() - cut["x"]
        assert z >= needed, \
            (f"gear {gear_id}: infeed to X{cut['x']} (h = {h:.3f}) at Z{z}, needs Z ≥ {needed:.3f} "
             f"to clear the blank")
        end = cut["pass"].end["Z"]
        assert end < -c.gear["b"], f"gear {gear_id}: pass ends at Z{end}, not beyond the far face Z{-c.gear['b']}"


@pytest.mark.parametrize("gear_id", GEARS)
def test_rapid_moves_along_z_clear_the_gear_tip(case, gear_id):
    """The G0 X retract (and any G0 changing Z) happens at a centre distance where the hob
    tip cannot touch the gear's tip cylinder."""
    c = case(gear_id)
    clear = c.tip_contact_distance()
    for cut in c.cuts():
        assert cut["retract"].end["X"] > clear, \
            f"gear {gear_id}: retract X{cut['retract'].end['X']} ≤ tip contact {clear:.3f}"
    for move in c.nc.moves_in("G0"):
        if "Z" in move.changed and move.start["X"] is not None:
            assert move.start["X"] > clear, \
                f"gear {gear_id}: rapid Z move {c.block(move.block).text!r} at X{move.start['X']} ≤ {clear:.3f}"


@pytest.mark.parametrize("gear_id", GEARS)
def test_last_cut_reaches_full_depth(case, gear_id):
    c = case(gear_id)
    last = c.cuts()[-1]["x"]
    expected = c.full_depth()
    assert abs(last - expected) <= DIAMETER_TOLERANCE, \
        f"gear {gear_id}: last cut X{last}, full depth (d_f2 + d_a0)/2 = " \
        f"({c.gear['df2']} + {c.hob['da0']})/2 = {expected:.3f}"


@pytest.mark.parametrize("gear_id, count", [(42, 1), (45, 2)])
def test_cut_count_by_module(case, gear_id, count):
    c = case(gear_id)
    xs = [cut["x"] for cut in c.cuts()]
    assert len(xs) == count, f"gear {gear_id} (m{c.gear['mn']:g}): cuts at {xs}"
    if count == 2:
        assert xs[0] > xs[1], f"rough X{xs[0]} must be outside finish X{xs[1]}"


def test_chosen_cuts_and_finish_stock(case):
    """§B3: the rough pass leaves radial stock s: a_r = a + s."""
    c = case(42, cuts=2, finish_stock=0.5)
    xs = [cut["x"] for cut in c.cuts()]
    assert len(xs) == 2
    assert xs[0] - xs[1] == pytest.approx(0.5, abs=0.001)
    assert xs[1] == pytest.approx(c.full_depth(), abs=DIAMETER_TOLERANCE)
    single = case(45, cuts=1)
    assert [cut["x"] for cut in single.cuts()] == [pytest.approx(single.full_depth(), abs=DIAMETER_TOLERANCE)]


# ---------------------------------------------------------------- values come from the gear

def test_programs_of_different_gears_differ_where_they_must(case):
    cases = {gear_id: case(gear_id) for gear_id in GEARS}
    teeth = {g: float(c.block(c.first("EGON")).call("EGON").args[4]) for g, c in cases.items()}
    assert teeth == {g: c.gear["z2"] for g, c in cases.items()}
    assert len(set(teeth.values())) == len(GEARS)
    last_x = {g: c.cuts()[-1]["x"] for g, c in cases.items()}
    assert len(set(last_x.values())) == len(GEARS), last_x
    assert len({c.lines[0] for c in cases.values()}) == len(GEARS)
    factors = {g: c.block(c.first("EGON")).call("EGON").args[6] for g, c in cases.items() if g in HELICAL}
    assert float(factors[43]) < 0 < float(factors[44])   # gear 43 right hand, 44 left hand (§A7)
    assert abs(float(factors[43])) != pytest.approx(abs(float(factors[44])))


# ---------------------------------------------------------------- the reader itself

def test_reader_on_a_hand_written_program():
    text = "\n".join([
        "%_N_T_MPF", ";$PATH=/_N_MPF_DIR", "; comment only",
        "N10 G90 G94", "G25 X10 Y-1 Z-50", "G26 X200 Y1 Z50", "WALIMON",
        "N20 G0 X100 Z30 ; rapid", "G0 A=-1.5", "EGDEF(C,B,1,Z,1)",
        'EGON(C,"FINE",B,-2,41,Z,0.123456,1)', "M1=3 S1=300", "M8",
        "G1 X50 F12.5", "Z-40 F30", "G0 X100", "M9", "EGOFS(C)", "M5", "M30",
    ])
    nc = read_program(text)
    assert [line for _, line in nc.comments] == ["$PATH=/_N_MPF_DIR", " comment only"]
    assert nc.blocks[0].number == 10 and nc.blocks[0].g == [90, 94]
    assert [(m.mode, m.end["X"], m.end["Z"], m.end["A"], m.feed) for m in nc.moves] == [
        ("G0", 100, 30, None, None), ("G0", 100, 30, -1.5, None),
        ("G1", 50, 30, -1.5, 12.5), ("G1", 50, -40, -1.5, 30), ("G0", 100, -40, -1.5, None)]
    assert nc.moves[3].start["X"] == 50 and nc.moves[3].changed == {"Z"}
    on = nc.block_with("EGON").call("EGON")
    assert on.args == ("C", "FINE", "B", "-2", "41", "Z", "0.123456", "1")
    assert nc.block_with("EGDEF").call("EGDEF").args == ("C", "B", "1", "Z", "1")
    spindle = nc.block_with("M3")
    assert spindle.words["S"] == 300
    assert nc.index("G25") < nc.index("WALIMON") < nc.index("motion")
    assert nc.index("M8") < nc.index("move G1") and nc.indexes("move G1")[-1] < nc.index("M9")
    assert nc.index("M9") < nc.index("EGOFS") < nc.index("M5") < nc.index("M30")
