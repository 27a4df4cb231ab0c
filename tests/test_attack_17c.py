"""Attacks on issue 17's rapid-through-material check (adversary review adv3): a G00 must run
through air only; a rapid that crosses material left standing by the job's own feeds breaks the
tool, however thin the material is along the rapid's way."""
from __future__ import annotations

import pytest

from engine.errors import EngineError
from engine.turning.material import Blank, check_rapids_in_air
from engine.turning.moves import Move

BLANK_RADIUS = 20.0                       # a Ø40 blank, Z0 … Z-50
FIN_FRONT, FIN_BACK = -5.0, -5.04         # a rib 0.04 mm wide left standing to the full blank
TURNED_RADIUS = 10.0                      # both sides of the rib turned down to Ø20
RAPID_RADIUS = 10.5                       # a G00 along Z at Ø21, below the rib's top (Ø40)


def fin_job(rapid_end_z: float) -> dict[int, list[list[Move]]]:
    """Turns Z0…Z-5 and Z-5.04…Z-10 to Ø20 (leaving the rib up to Ø40), then rapids back along
    Z at Ø21 — through the rib."""
    d = 2 * TURNED_RADIUS
    front = [Move("rapid", 0.0, 42), Move("feed", 0.0, d), Move("feed", FIN_FRONT, d), Move("feed", FIN_FRONT, 42)]
    back = [Move("rapid", FIN_BACK, 42), Move("feed", FIN_BACK, d), Move("feed", -10.0, d), Move("feed", -10.0, 42),
            Move("rapid", -10.0, 2 * RAPID_RADIUS), Move("rapid", rapid_end_z, 2 * RAPID_RADIUS)]
    return {1: [front, back]}


@pytest.mark.parametrize("rapid_end_z", [0.0, -0.013, -0.027])
def test_a_rapid_through_a_thin_rib_left_standing_is_refused_wherever_it_ends(rapid_end_z):
    """The rib is FIN_FRONT - FIN_BACK = 0.04 mm thick along the rapid and 9.5 mm tall above it:
    the tool hits it whatever the rapid's length is (0.05 mm sampling must not decide)."""
    rib = FIN_FRONT - FIN_BACK
    assert rib > 0.01 and BLANK_RADIUS > RAPID_RADIUS > TURNED_RADIUS
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(Blank(0.0, -50.0, BLANK_RADIUS, False), fin_job(rapid_end_z), {1: "ROUGH"}, (100.0, 50.0))


def test_a_rapid_from_one_plunge_to_the_next_across_the_material_between_is_refused():
    """Two plunges to Ø20 at Z-5 and Z-5.04 leave 0.04 mm of blank between them up to Ø40; a
    G00 along Z at Ø20 from one plunge's bottom to the other's runs through it."""
    plunges = [Move("rapid", FIN_FRONT, 42), Move("feed", FIN_FRONT, 20), Move("rapid", FIN_FRONT, 42),
               Move("rapid", FIN_BACK, 42), Move("feed", FIN_BACK, 20), Move("rapid", FIN_BACK, 42),
               Move("rapid", FIN_FRONT, 42), Move("rapid", FIN_FRONT, 20), Move("rapid", FIN_BACK, 20)]
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(Blank(0.0, -50.0, BLANK_RADIUS, False), {1: [plunges]}, {1: "GROOVE"}, (100.0, 50.0))
