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


def test_the_assumed_blank_reaches_as_far_in_z_as_the_job_feeds():
    """Without a stored stock the blank is assumed as large as the job suggests (fail closed):
    its radius covers every feed, and so must its Z. A facing feed at Z+1 in front of a profile
    ending at Z0 says the blank stands 1 mm in front of the part; the rough's approach G00 to
    Z+0.5 at Ø24 runs into that stock before the face is cut."""
    from engine.turning.material import job_blank
    profile_front, profile_back, profile_top = 0.0, -50.0, 15.0
    face_z = 1.0
    rough = [Move("rapid", 0.5, 24), Move("feed", -20.0, 24), Move("feed", -20.0, 40)]
    face = [Move("rapid", face_z, 34), Move("feed", face_z, 0), Move("feed", face_z + 1, 0)]
    passes = {1: [rough], 2: [face]}
    blank = job_blank(None, (profile_front, profile_back, profile_top), passes)
    assert blank.z_front >= face_z
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(blank, passes, {1: "ROUGH", 2: "FACE"}, (100.0, 50.0))
