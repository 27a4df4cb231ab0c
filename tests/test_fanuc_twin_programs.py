"""Issue 30's first "Must show": for random gears of every class and both hands, the Fanuc program
and the 840D program of the same gear, made on the seeded hobbers given the same axis senses, make
the same moves (X, Y, Z, A, feeds, dwells, spindle), and their couplings turn the table the same
way at the same ratio, both equal to docs/reference/fanuc-egb.md §F5 computed here from the gear,
the job's hob and the senses (the helical term too: EGON's Z factor and the control's compensation
from G81's Q and P). A gear one machine refuses, the other refuses too, except what Fanuc's G81
cannot write (a tangential worm-wheel feed: no Y term), refused on Fanuc in one line."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest
from helpers.twin_programs import couplings_840d, couplings_fanuc, moves, p_rounding_bound, reference_coupling
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

GEAR_ID = 5301   # hobber-fanuc numbers its programs O(1000 + gear id): O6301
SIEMENS, FANUC = "hobber-840d", "hobber-fanuc"
INSERT_GEAR = """
INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, tip_diameter,
                  cone_angle, crowning, material, hardness, quality_grade, quantity, module_kind)
VALUES (%s, %s, %s, %s, 20, %s, %s, %s, %s, %s, %s, '45', 200, 8, 10, %s)"""
INSERT_UNIT = """INSERT INTO gear_unit (gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top)
VALUES (%s, 2, %s, %s, %s, %s, %s)"""
SET_SENSES = "UPDATE machine SET b_direction = %s, c_direction = %s, z_direction = %s WHERE name = %s"
SET_HELIX_SIGN = "UPDATE machine SET egb_helix_sign = %s WHERE name = %s"
HOB_OF_PROGRAM = """SELECT h.starts, h.hand FROM program p JOIN job j ON j.id = p.job_id JOIN hob h ON h.id = j.hob_id
WHERE p.id = %s"""
CLASSES = ["spur", "helical", "taper", "crowned", "worm_wheel", "duplex"]   # each drawn 20 times


@st.composite
def gears(draw, gear_class: str):
    """A gear of the class; helical, taper and crowned gears of either hand (β 0 or 5–30°)."""
    module = 3.0 if gear_class == "worm_wheel" else draw(st.sampled_from([1.5, 2.0, 2.5, 3.0, 4.0]))
    teeth = draw(st.integers(12, 90))
    helix, hand = 0.0, None
    if gear_class in ("helical", "taper", "crowned") and (gear_class == "helical" or draw(st.booleans())):
        helix, hand = round(draw(st.floats(5, 30)), 3), draw(st.sampled_from(["R", "L"]))
    if gear_class == "worm_wheel":
        helix, hand = 4.05, "R"   # the seeded worm-wheel hob's lead angle (H-WW-M3-R1), as gear 53
    width = round(draw(st.floats(8, 50)), 2)
    tip = round(module * teeth / math.cos(math.radians(helix)) + 2 * module, 3)
    cone = draw(st.sampled_from([-1, 1])) * draw(st.floats(1, 8)) if gear_class == "taper" else None
    crowning = draw(st.floats(0.005, 0.04)) if gear_class == "crowned" else None
    gear = dict(gear_class=gear_class, module=module, teeth=teeth, helix_angle=helix, hand=hand,
                face_width=width, tip=tip, cone=cone, crowning=crowning)
    unit = None
    if gear_class == "duplex":
        teeth2 = draw(st.integers(12, 90))
        tip2 = module * (teeth2 + 2)
        unit = (teeth2, round(draw(st.floats(8, 40)), 2), tip2, tip2 - 4.5 * module,
                round(-width - draw(st.floats(5, 80)), 2))
    choices = Choices(cuts=draw(st.sampled_from([None, 1, 2])),
                      feed_mode=None if gear_class == "worm_wheel" else   # a radial plunge has no axial pass
                      draw(st.sampled_from(["climb", "conventional", "conventional-climb"])),
                      tailstock=draw(st.booleans()), worm_feed=draw(st.sampled_from(["radial", "tangential"])),
                      shift_y=draw(st.sampled_from([0.0, 12.5])))
    senses = {axis: draw(st.sampled_from([1, -1])) for axis in "bcz"}
    return gear, unit, choices, senses, draw(st.sampled_from([1, -1]))


def _insert(conn, gear: dict, unit) -> None:
    conn.execute(INSERT_GEAR, (GEAR_ID, gear["gear_class"], gear["module"], gear["teeth"], gear["helix_angle"],
                               gear["hand"], gear["face_width"], gear["tip"], gear["cone"], gear["crowning"],
                               "normal" if gear["gear_class"] == "worm_wheel" else None))   # as the seeded wheel
    if unit:
        conn.execute(INSERT_UNIT, (GEAR_ID, *unit))


def _give_both_machines(conn, senses: dict, helix_sign: int) -> None:
    for machine in (SIEMENS, FANUC):
        conn.execute(SET_SENSES, (senses["b"], senses["c"], senses["z"], machine))
    conn.execute(SET_HELIX_SIGN, (helix_sign, FANUC))


def _made(conn, machine: str, choices: Choices):
    """The stored program of the gear on `machine`, or the one-line refusal."""
    try:
        with conn.transaction():
            return instantiate_gear(conn, GEAR_ID, machine=machine, choices=choices)
    except EngineError as error:
        assert "\n" not in str(error)
        return str(error)


def _expected(gear: dict, unit, hob: dict, senses: dict) -> list:
    """The reference coupling of each unit the program cuts, in order (a cluster gear's unit 2 has
    its own teeth). A radial worm-wheel plunge feeds X only: neither program couples Z (the 840D's
    EGON has no Z term), so its Z term is 0."""
    teeth = [gear["teeth"]] + ([unit[0]] if unit else [])
    found = [reference_coupling(gear | {"teeth": z2, "hand": gear["hand"] or "R"}, hob, senses) for z2 in teeth]
    if gear["gear_class"] == "worm_wheel":
        found = [replace(coupling, per_z=0.0) for coupling in found]
    return found


def _assert_twins(conn, gear, unit, siemens, fanuc, senses, helix_sign) -> None:
    assert moves(fanuc.lines, "fanuc") == moves(siemens.lines, "840d")
    hob = dict(zip(("starts", "hand"), conn.execute(HOB_OF_PROGRAM, (fanuc.program_id,)).fetchone()))
    expected = _expected(gear, unit, hob, senses)
    on_840d, on_fanuc = couplings_840d(siemens.lines), couplings_fanuc(fanuc.lines, helix_sign)
    assert len(on_840d) == len(on_fanuc) == len(expected)
    for want, egon, g81 in zip(expected, on_840d, on_fanuc):
        assert egon.per_hob == pytest.approx(want.per_hob, abs=1e-12)
        assert g81.per_hob == pytest.approx(want.per_hob, abs=1e-12)
        assert egon.per_z == pytest.approx(want.per_z, abs=5e-7 + 1e-12)   # EGON's Z factor to 6 decimals
        assert g81.per_z == pytest.approx(want.per_z, abs=p_rounding_bound(gear))


@pytest.mark.slow
@pytest.mark.parametrize("gear_class", CLASSES)
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_the_fanuc_and_840d_programs_of_a_gear_make_the_same_moves_and_coupling(conn, gear_class, data):
    gear, unit, choices, senses, helix_sign = data.draw(gears(gear_class))
    with conn.transaction(force_rollback=True):
        _insert(conn, gear, unit)
        _give_both_machines(conn, senses, helix_sign)
        siemens, fanuc = _made(conn, SIEMENS, choices), _made(conn, FANUC, choices)
        tangential = gear["gear_class"] == "worm_wheel" and choices.worm_feed == "tangential"
        if tangential:
            event("tangential worm wheel: refused on Fanuc")
            assert isinstance(fanuc, str) and "tangential" in fanuc
        elif isinstance(siemens, str) or isinstance(fanuc, str):
            event(f"refused on both: {str(siemens)[:90]}")
            assert isinstance(siemens, str) and isinstance(fanuc, str), (siemens, fanuc)
        else:
            event(f"twins: {gear['gear_class']} {gear['hand'] or 'spur'}")
            _assert_twins(conn, gear, unit, siemens, fanuc, senses, helix_sign)


GEAR_ROW = "SELECT gear_class, module::float, teeth, helix_angle::float, hand FROM gear WHERE id = %s"
SENSES = "SELECT b_direction, c_direction, z_direction, egb_helix_sign FROM machine WHERE name = %s"


@pytest.mark.parametrize("gear_id", [42, 43])
def test_the_seeded_gears_make_twin_programs_on_the_seeded_hobbers(conn, gear_id):
    """The seeded spur gear 42 and helical gear 43 on the seeded records as they are (their senses
    the same; the Fanuc record's egb_helix_sign as it states it)."""
    gear = dict(zip(("gear_class", "module", "teeth", "helix_angle", "hand"),
                    conn.execute(GEAR_ROW, (gear_id,)).fetchone()))
    *senses, _ = conn.execute(SENSES, (SIEMENS,)).fetchone()
    *fanuc_senses, helix_sign = conn.execute(SENSES, (FANUC,)).fetchone()
    assert senses == fanuc_senses
    siemens, fanuc = (instantiate_gear(conn, gear_id, machine=machine) for machine in (SIEMENS, FANUC))
    _assert_twins(conn, gear, None, siemens, fanuc, dict(zip("bcz", senses)), helix_sign)
