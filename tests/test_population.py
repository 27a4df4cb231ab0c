"""Every gear a skilled programmer would hob (issue 29, Must show): on a population drawn here
from the reference ranges (tests/helpers/hob_population.py: module 1–8 on a hobber rated for it,
12–120 teeth, every hobbing class, a DIN 8002-like hob library), at least 99 % of the gears that
are hobbing work become programs the verifier and the simulation prove (a dry-run batch proves
each and stores nothing), and every refusal names what was tried and a physical reason. Cluster
gears no hob of the library fits between its units are a shaper's job, decided from the geometry
in the helper, not by the engine; they are counted apart (and must be refused, not made)."""
from __future__ import annotations

import psycopg
import pytest
from helpers.hob_population import FIRST, populate, shaper_jobs

from engine.programs.instantiate import instantiate_gears
from engine.programs.options import RunMode

COUNT = 300
SEED = 29
SHARE = 0.99
# What a refusal names: a body that meets another (unit, fixture, tailstock, table), a limit of the
# machine or the tool, or the simulation's finding, with its numbers.
PHYSICAL = ("reaches", "runs", "into the", "exceeds", "limit", "travel", "beyond", "too ", "need")


def refusals(batch) -> dict[int, str]:
    """gear id → its reason, from the batch's skipped lines "gear 7: <reason>"."""
    return {int(line.split(":")[0].split()[1]): line.partition(": ")[2] for line in batch.skipped}


@pytest.mark.slow   # 300 gears planned, simulated and searched: about half a minute
def test_at_least_99_percent_of_the_hobbing_work_is_proved_and_every_refusal_says_why(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        populate(conn, COUNT, SEED)
        shaped = shaper_jobs(conn)
        batch = instantiate_gears(conn, FIRST, FIRST + COUNT - 1, mode=RunMode(dry_run=True, skip_bad=True))
        stored = conn.execute("SELECT count(*) FROM program p JOIN job j ON j.id = p.job_id "
                              "WHERE j.gear_id >= %s", (FIRST,)).fetchone()[0]
    assert stored == 0, "a dry run stores nothing"
    refused = refusals(batch)
    work = COUNT - len(shaped)
    proved = work - len(set(refused) - shaped)
    assert work >= 0.9 * COUNT, f"the population is hobbing work: {len(shaped)} set apart"
    assert proved >= SHARE * work, (f"{proved} of {work} proved; refused: "
                                    f"{[refused[g][:200] for g in sorted(set(refused) - shaped)]}")
    assert shaped <= set(refused), f"cluster gears no hob fits were made: {sorted(shaped - set(refused))}"
    for gear_id, reason in refused.items():
        assert "\n" not in reason and ("tried: [" in reason or "the first choice [" in reason), \
            f"gear {gear_id}: {reason[:300]}"
        assert any(word in reason for word in PHYSICAL), f"gear {gear_id}: no physical reason: {reason[:300]}"
