"""Notes on a hobbing job that do not stop it but that the operator must read before it runs
(issue 14): one line each, said by `engine instantiate` and kept with the program."""
from __future__ import annotations

import math

from ..notes import Note


def hunting_tooth_notes(gear, hob) -> list[str]:
    """A z0-start hob on z2 teeth with a common factor g = gcd(z0, z2) > 1 has no hunting tooth:
    per hob revolution the table turns z0/z2, so hob thread k only ever meets the gaps k, k + g,
    k + 2g, …; each hob tooth always meets the same gaps and the threads' spacing and form errors
    repeat around the gear instead of averaging out (Phillips, "common factor ratio"). A warning,
    not a refusal: for a roughing or a coarse grade it may be acceptable. Every toothed unit of
    the gear (duplex) is checked."""
    counts = [gear.teeth] + [unit.teeth for unit in getattr(gear, "units", ())]
    return [_note(gear.id, hob, teeth) for teeth in dict.fromkeys(counts) if math.gcd(hob.starts, teeth) > 1]


def _note(gear_id: int, hob, teeth: int) -> str:
    factor = math.gcd(hob.starts, teeth)
    return Note(f"gear {gear_id}: hob {hob.id} has {hob.starts} starts and the gear {teeth} teeth, common factor "
            f"{factor} (no hunting tooth): each hob thread cuts only one gap in {factor}, "
            "so the hob's errors repeat on the gear; "
            f"choose a hob whose starts share no factor with {teeth} where the grade needs it", "no hunting tooth")


# The kind of cut (reference §C rows) of each cut name a hobbing job stores; a single cut is a rough one.
CUT_KIND_BY_NAME = {"ROUGH": "rough", "SINGLE": "rough", "FINISH": "finish"}

