"""Adversary 29 against 9844952 (worm-wheel hobs catalogued by the worm's axial module). The
commit's own rule (docs/reference/hobbing.md §B10, DIN 3975): the worm's axial pitch π·m_x is the
wheel's transverse pitch π·m_n2/cos β2, and "an oversize or resharpened hob may differ a little in
lead angle γ0, never in axial pitch". A hob stated axial is held to that (module test to 1e-6 mm);
a hob stated normal is still matched by its normal module, its lead within 0.5° of the wheel's
helix (hob_matching.LEAD_ANGLE_TOLERANCE), so its axial pitch π·m_n0/cos γ0 may differ from the
wheel's by (cos β2/cos γ0 − 1), 0.33 % at a 4-start worm's 26.6° lead: the wheel's teeth are cut for
another worm. The same physical hob stated axial is refused: what the engine accepts depends on
how the record states the module, not on the hob.

The wheel: a 4-start worm of axial module m_x 3, quotient q 8 (d1 24 mm), so β2 = atan(4/8) =
26.565°; z2 40, tip 126, root 112.5 (d2 = m_x·z2 = 120, addendum m_x, dedendum 1.25·m_x). The hob:
4 starts, right hand, normal module m_n0 = m_x·cos β2 (the wheel's normal module), d_a0 30.4, so
its lead (§B1: sin γ0 = z0·m_n0/(d_a0 − 2.5·m_n0)) is 27.0°, 0.37° off the wheel's helix."""
from __future__ import annotations

import math

import pytest

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

M_X, STARTS, Q, Z2, HOB_TIP = 3.0, 4, 8.0, 40, 30.4
BETA = math.degrees(math.atan(STARTS / Q))          # the worm's lead = the wheel's helix (DIN 3975)
M_N = M_X * math.cos(math.radians(BETA))            # the wheel's normal module
WHEEL = 951


def hob_lead(normal_module: float) -> float:
    """§B1: sin γ0 = z0·m_n0/d_m0, d_m0 = d_a0 − 2.5·m_n0 (degrees)."""
    return math.degrees(math.asin(STARTS * normal_module / (HOB_TIP - 2.5 * normal_module)))


@pytest.fixture
def wheel(conn):
    conn.execute("INSERT INTO gear (id, gear_class, module, module_kind, teeth, helix_angle, hand, face_width, "
                 "tip_diameter, root_diameter, material, hardness, quality_grade, quantity) "
                 "VALUES (%s, 'worm_wheel', %s, 'axial', %s, %s, 'R', 25, %s, %s, 'CuSn12', 90, 8, 20)",
                 (WHEEL, M_X, Z2, round(BETA, 6), M_X * Z2 + 2 * M_X, M_X * Z2 - 2.5 * M_X))
    conn.execute("DELETE FROM hob WHERE purpose = 'worm_wheel'")
    return conn


def add_hob(conn, module: float, kind: str) -> None:
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, purpose, "
                 "module_kind) VALUES ('WW-4', %s, %s, %s, 90, 'R', 'A', 'worm_wheel', %s)",
                 (round(module, 6), STARTS, HOB_TIP, kind))


def test_the_hob_is_within_the_lead_tolerance_but_not_of_the_worms_pitch():
    gamma = hob_lead(M_N)
    assert 0.3 < gamma - BETA < 0.5
    hob_axial = M_N / math.cos(math.radians(gamma))          # m_x0 = m_n0/cos γ0
    assert hob_axial == pytest.approx(3.0099, abs=1e-4)
    assert math.pi * (hob_axial - M_X) == pytest.approx(0.031, abs=0.001)   # mm on every pitch


@pytest.mark.parametrize("feed", ["radial", "tangential"])
def test_a_hob_stated_normal_with_another_axial_pitch_is_refused(wheel, feed):
    """Was stored: instantiate_gear proved and kept a program that cut 40 teeth 0.031 mm apart too
    far on the pitch circle (0.33 % of π·m_x) for the drawing's worm. Now every worm-wheel hob is
    held to the wheel's axial module, however its record states its module."""
    add_hob(wheel, M_N, "normal")
    with pytest.raises(EngineError):
        program = instantiate_gear(wheel, WHEEL, choices=Choices(worm_feed=feed))
        print(program.text)


def test_the_same_hob_stated_axial_is_refused(wheel):
    """The same physical hob recorded by its axial module m_x0 = m_n0/cos γ0: refused (the module
    test). Held before; now the two statements of one hob are judged alike."""
    gamma = hob_lead(M_N)
    add_hob(wheel, M_N / math.cos(math.radians(gamma)), "axial")
    with pytest.raises(EngineError, match="axial"):
        instantiate_gear(wheel, WHEEL, choices=Choices(worm_feed="radial"))
