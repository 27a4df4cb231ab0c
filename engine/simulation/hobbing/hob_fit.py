"""Does the hob record fit the gear record? The same required properties `engine hobs match`
tests (engine.gears.hob_matching.HOB_TESTS, for the hob's purpose): normal module and pressure
angle equal (a worm wheel's axial module is converted to its normal module when its record is
read, engine.gears.records.normal_module; hob records state the normal module), the accuracy
class its grade needs, a worm-wheel hob of the wheel's hand and lead angle (reference §B10), and
the hob long enough for the generating zone (§B15). The hand of a cylindrical gear's hob is a
preference only (§B2: prefer the gear's hand; the swivel and coupling checks hold the hand the
program uses). Held from the records alone, not from the job that named the hob: a job copied
by hand with another hob is refused here."""
from __future__ import annotations

from ...gears.hob_matching import HOB_TESTS, need_of
from ...gears.records import Gear, Hob


def hob_fit_problem(gear: Gear, hob: Hob) -> str | None:
    """The first required property of `engine hobs match` the hob lacks for the gear, or None."""
    need = need_of(gear, hob.purpose)
    for test in HOB_TESTS:
        if hob.purpose not in test.purposes or test.fits is None or test.fits(gear, hob, need):
            continue
        assert test.wanted is not None and test.offered is not None   # a required test says both
        return (f"hob {hob.id} does not fit gear {gear.id}: the gear needs {test.wanted(gear, need)}, the hob has "
                f"{test.offered(hob)} (hob and gear records, reference §B; `engine hobs match --gear {gear.id}` "
                "names the hobs that fit)")
    return None
