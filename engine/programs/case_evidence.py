"""What `engine cases confirm` takes from job.cutting, held to what the job's program ran (issue 26).

confirm_job_cases (the database) makes one cutting case per cut kind of job.cutting: the hob
speed n0 and each kind's axial and radial feeds (mm/min). The database compares only n0 with the
program's trace; a runner can set job.cutting's rough feeds to 150 and 90 mm/min while the
program, the rendering of the job (engine.programs.rendering: MATCH, proved), cuts at 38.8 and
13.3. So before the case is made, every value it takes is compared with the program's own trace:
n0 with the job's n0 it ran, each kind's feeds with the first cut of that kind it switched on
(ROUGH, or SINGLE: a single cut runs at the roughing feeds, engine.hobbing.passes.feeds; FINISH),
and a kind the program never cut is refused. Feeds are equal within 0.15 mm/min: job.cutting
holds the feed per minute rounded to 0.1, the F word its value rounded down to 0.1
(engine.gears.cutting_data.programmed_feed), so one exact feed can show as 24.7 and 24.6. A
feed the trace does not record (a taper cut reads feed_slant, not feed_axial) is taken from the
job's module parameters, which the MATCH check proved are what the program was rendered from.

The radial feed of a finish cut is not compared: a cylindrical program cuts FINISH at the roughing
radial feed (its infeed is in air; engine.hobbing.passes.feeds reads cutting.radial_feed), while
job.cutting stores the finish cases' radial feed, so the two differ for every two-cut cylindrical
job the engine makes; that value is not vouched for by any program (docs/design.md, the rendering
check). A worm wheel's finishing plunge runs at it (issue 29, engine.hobbing.worm_wheel.cut_feeds)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection

FEED_TOLERANCE = 0.15   # mm/min: a feed rounded half up to 0.1 against the same feed rounded down to 0.1
KIND_OF_CUT = {"ROUGH": "rough", "SINGLE": "rough", "FINISH": "finish"}
# (job.cutting key of the kind, the cut's values that may hold it): a worm wheel feeds tangentially
FEEDS = (("axial_feed", ("feed_axial", "feed_tangential")), ("radial_feed", ("feed_radial",)))
UNCHECKED_FEEDS = {("finish", "radial_feed")}
PROGRAM_AND_CUTTING = """
SELECT p.trace, j.cutting, j.module_params FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s"""


def check_case_evidence(conn: Connection, job_id: int, program_id: int) -> None:
    """EngineError (one line, nothing confirmed) for a value of job.cutting the program did not run."""
    found = conn.execute(PROGRAM_AND_CUTTING, (program_id,)).fetchone()
    if found is None:   # checked_last_program found it in this transaction, the job locked
        raise EngineError(f"program {program_id} does not exist; nothing confirmed")
    trace, cutting, module_params = found
    inputs = (trace or {}).get("inputs") or {}
    said = f"job {job_id}: job.cutting"
    ran = (inputs.get("job") or {}).get("n0")
    if isinstance(cutting, dict) and cutting.get("hob_speed") != ran:
        raise _refused(said, f"hob_speed {cutting.get('hob_speed')} r/min", f"n0 = {ran} r/min", program_id)
    cuts = _first_cuts(inputs, module_params if isinstance(module_params, dict) else {})
    for kind in ("rough", "finish"):
        if isinstance(cutting, dict) and kind in cutting:
            _check_kind(said, kind, cutting[kind], cuts.get(kind), program_id)


def _check_kind(said: str, kind: str, stored, cut: dict | None, program_id: int) -> None:
    if cut is None:
        raise EngineError(f"{said} has a {kind} cut, but program {program_id} switches on no {kind} cut; "
                          "nothing confirmed")
    for name, words in FEEDS:
        if (kind, name) in UNCHECKED_FEEDS:
            continue
        value = stored.get(name) if isinstance(stored, dict) else None
        made = next((cut[word] for word in words if isinstance(cut.get(word), (int, float))), None)
        if not _same_feed(value, made):
            raise _refused(said, f"{kind} {name} {value} mm/min", f"{made} mm/min", program_id)


def _same_feed(value, made) -> bool:
    numbers = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (value, made))
    return numbers and abs(value - made) <= FEED_TOLERANCE


def _first_cuts(inputs: dict, module_params: dict) -> dict[str, dict]:
    """{cut kind: the first cut of that kind the program switches on} from its trace's inputs
    (the values its rows read), completed by the job's module parameters the program was rendered
    from (a taper cut reads only feed_slant, the axial feed along the cone)."""
    found: dict[str, dict] = {}
    modules = [(key.removeprefix("module "), value) for key, value in inputs.items() if key.startswith("module ")]
    for key, cut in sorted(modules, key=lambda item: _number(item[0])):
        if key.startswith("cutmotion:") and isinstance(cut, dict) and cut.get("cut_on") is True:
            kind = KIND_OF_CUT.get(str(cut.get("cut_name")))
            if kind:
                stored = module_params.get(key)
                found.setdefault(kind, {**(stored if isinstance(stored, dict) else {}), **cut})
    return found


def _number(key: str) -> int:
    number = key.partition(":")[2]
    return int(number) if number.isdecimal() else 0


def _refused(said: str, stored: str, ran: str, program_id: int) -> EngineError:
    return EngineError(f"{said} says {stored}, but its program {program_id} ran {ran}: a case holds only what "
                       "the program ran; fix job.cutting or make the program again; nothing confirmed")
