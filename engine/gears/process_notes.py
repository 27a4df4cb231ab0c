"""Notes on a hobbing job that do not stop it but that the operator must read before it runs
(issue 14): one line each, said by `engine instantiate` and kept with the program."""
from __future__ import annotations

import math

from .cutting_data import feed_maximum


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
    return (f"gear {gear_id}: hob {hob.id} has {hob.starts} starts and the gear {teeth} teeth, common factor {factor} "
            f"(no hunting tooth): each hob thread cuts only one gap in {factor}, "
            "so the hob's errors repeat on the gear; "
            f"choose a hob whose starts share no factor with {teeth} where the grade needs it")


CUT_KIND_BY_NAME = {"ROUGH": "rough", "SINGLE": "rough", "FINISH": "finish"}


def stored_feed_notes(job_id: int, params: dict, module_params: dict) -> list[str]:
    """A stored job's axial feeds above the maximum for its module and hob starts (reference §C),
    one line per cut. Feeds edited into job.params in SQL are the engineer's deliberate record, so
    they are warned about, not refused (an override through the engine is refused: CuttingData.
    with_overrides). A job whose values are not numbers gets no note: the template says the rest."""
    try:
        table_speed = float(params["n0"]) * int(params["z0"]) / int(params["z2"])
        module, starts = float(params["mn"]), int(params["z0"])
        cuts = [(CUT_KIND_BY_NAME[cut["cut_name"]], float(cut["feed_axial"]) / table_speed)
                for cut in module_params.values()
                if isinstance(cut, dict) and cut.get("cut_on") and cut.get("cut_name") in CUT_KIND_BY_NAME
                and "feed_axial" in cut]
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        return []
    return [f"job {job_id}: {kind}: axial feed {feed:.2f} mm per workpiece rev is above the {limit:.2f} maximum for "
            f"m{module:g} with a {starts}-start hob (reference §C); check job.params before running it"
            for kind, feed in cuts if feed > (limit := feed_maximum(module, kind, starts)) + 1e-9]
