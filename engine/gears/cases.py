"""Cutting data by case-based reasoning over the machining history (design notes §6; paper §4).

For each cut kind the nearest past cuts (weighted distance over gear and hob features) are
transferred to this gear and hob through what carries over between hobs and gears: the
cutting speed v = π·d_a0·n0/1000 and the feeds per workpiece revolution f = v_f/(n0·z0/z2)
(docs/reference/hobbing.md §B4, §B5). Proposals are checked against the typical ranges of §C.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
import pandas as pd
import psycopg
from msgspec.structs import replace
from psycopg import sql

from ..csv_reader import (
    CsvError,
    read_csv_file,
    refuse,
)
from ..db.connection import scalar
from ..db.listing import records
from ..errors import EngineError
from ..machines.records import Machine, hobbing_machine
from ..paths import SEED_DIR
from .case_base import (
    CASE_COLUMNS,
    CUT_KINDS,
    FEED_BOUNDED,
    CaseBase,
    KindProposal,
    feeds_per_minute,
    feeds_per_rev,
)
from .case_import import CASE_KIND, FEATURE_COLUMNS, VALUE_COLUMNS
from .cutting_data import CuttingData
from .hob_matching import choose_hob
from .models import model_for_class
from .records import Gear, Hob, load_gear, load_hobs
from .speed_table import TOOLS, speeds_of, tool_of

if TYPE_CHECKING:
    from ..db.connection import Connection

FLOAT_COLUMNS = ("module", "hardness", "hob_tip_diameter", *VALUE_COLUMNS)
INTEGER_COLUMNS = ("teeth", "quality_grade", "hob_starts", "job_id")
SEED_FILE = SEED_DIR / "cases.csv"

# Typical axial feed per workpiece revolution [mm/rev], single-start hob, steel, wet (§C):
# the first row whose module is at least the gear's (the last row beyond).
AXIAL_FEED_RANGE = pd.DataFrame([
    (1.0, 1.0, 2.0, 0.5, 1.0), (2.0, 1.5, 3.0, 0.8, 1.5), (3.0, 2.0, 3.5, 1.0, 2.0), (4.0, 2.0, 4.0, 1.0, 2.0),
], columns=["module", "rough_low", "rough_high", "finish_low", "finish_high"])

CUTTING = {"rough": "roughing", "finish": "finishing"}


class Suggestion(msgspec.Struct, frozen=True):
    gear: Gear
    hob: Hob
    machine: Machine
    cutting: CuttingData
    cases: pd.DataFrame                  # the nearest cases per cut kind, with `distance`
    proposals: dict                      # cut kind -> KindProposal
    notes: list = []
    hob_reason: str = ""

    def feeds(self, cut: str) -> dict:
        """Axial and radial feed of one cut kind, per workpiece revolution and per minute."""
        axial, radial = feeds_per_rev(self.cutting, cut)
        return {"axial_feed_per_rev": axial, "radial_feed_per_rev": radial,
                **feeds_per_minute(self.cutting, self.gear, self.hob, cut)}

    def case_ids(self, cut_kinds=CUT_KINDS) -> list[int]:
        return [case_id for cut in cut_kinds for case_id in self.proposals[cut].case_ids]


CASE_RECORDS = """
SELECT id AS case_id, module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts,
       hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source, job_id, created_at
FROM cutting_case ORDER BY id"""


def case_records(conn: Connection) -> list[dict]:
    """The machining history as a person looks into it (`engine cases list`): one record per case,
    its id under case_id, numbers as floats."""
    return records(conn.execute(CASE_RECORDS))


def list_cases(conn: Connection) -> pd.DataFrame:
    """The machining history, one row per case, numbers as floats."""
    query = sql.SQL("SELECT {} FROM cutting_case ORDER BY id").format(
        sql.SQL(", ").join(map(sql.Identifier, CASE_COLUMNS)))
    cases = pd.DataFrame(conn.execute(query).fetchall(), columns=list(CASE_COLUMNS))
    return cases.astype({"id": "int64", **{column: float for column in FLOAT_COLUMNS},
                         **{column: "Int64" for column in INTEGER_COLUMNS}})


def suggest(conn: Connection, gear: Gear, hob: Hob, machine: Machine, *, top: int = 3) -> Suggestion:
    """Cutting data for this gear, hob and machine from the `top` nearest cases per cut kind."""
    return suggest_from(load_case_base(conn), gear, hob, machine, top=top)


def load_case_base(conn: Connection) -> CaseBase:
    """The history read once for many suggestions (a batch)."""
    return CaseBase.load(conn)


def suggest_from(base: CaseBase, gear: Gear, hob: Hob, machine: Machine, *, top: int = 3) -> Suggestion:
    """`suggest` over a case base already read (`load_case_base`), with the nearest cases as a
    table and the plausibility notes."""
    cutting, proposals, found = base.cutting_data(gear, hob, machine, top)
    rows = [base.records[case.position] | {"distance": distance}
            for nearest in found.values() for distance, case in nearest]
    table = pd.DataFrame(rows, columns=[*CASE_COLUMNS, "distance"])
    notes = plausibility_notes(gear, hob, machine, cutting, proposals)
    return Suggestion(gear, hob, machine, cutting, table, proposals, notes)


def suggest_for_gear(conn: Connection, gear_id: int, machine_name: str | None = None, *, top: int = 3) -> Suggestion:
    """`engine suggest`: the hob the library chooses for the gear, and its cutting data."""
    gear = load_gear(conn, gear_id)
    machine = hobbing_machine(conn, machine_name)
    model = model_for_class(conn, gear.gear_class) if gear.gear_class else None
    choice = choose_hob(gear, load_hobs(conn), purpose=model.hob_purpose if model else "cylindrical")
    suggestion = suggest(conn, gear, choice.hob, machine, top=top)
    return replace(suggestion, hob_reason=choice.reason)


def plausibility_notes(gear: Gear, hob: Hob, machine: Machine, cutting: CuttingData, proposals: dict) -> list[str]:
    notes = list(cutting.notes) + [note for proposal in proposals.values() for note in _feed_note(gear, proposal)]
    notes += _speed_notes(gear, hob, proposals)
    exact_speed = 1000 * cutting.cutting_speed / (math.pi * hob.tip_diameter)
    if exact_speed > machine.spindle_max:
        notes.append(f"hob speed {exact_speed:.0f} r/min capped at {machine.name}'s spindle maximum "
                     f"{machine.spindle_max:g} r/min: "
                     f"v is {math.pi * hob.tip_diameter * cutting.hob_speed / 1000:.1f} m/min")
    table_speed = cutting.hob_speed * hob.starts / gear.teeth
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        notes.append(f"table speed {table_speed:.1f} r/min exceeds {machine.name}'s {machine.table_speed_max:g} r/min; "
                     "lower the hob speed")
    return notes


def _feed_note(gear: Gear, proposal: KindProposal) -> list[str]:
    """The proposal's axial feed outside the §C row's typical range, said with the row it was read
    from (an m2.5 gear reads the row up to m3: it is not an m3 gear). A feed the engine lowered to
    its own bound (the §C maximum or the chip-thickness bound, whose note says so) is not
    complained of: below the typical range there is the bound's doing, not the cases'."""
    at_least = AXIAL_FEED_RANGE[AXIAL_FEED_RANGE.module >= gear.module]
    row = (at_least if not at_least.empty else AXIAL_FEED_RANGE).iloc[0]
    low, high = row[f"{proposal.cut}_low"], row[f"{proposal.cut}_high"]
    if low <= proposal.axial_feed <= high or proposal.source.endswith(FEED_BOUNDED):
        return []
    side = "above" if proposal.axial_feed > high else "below"
    check = f"; check the feed definition of case(s) {', '.join(f'#{i}' for i in proposal.case_ids)}" \
        if proposal.case_ids else ""
    return [f"{proposal.cut}: axial feed {proposal.axial_feed:.2f} mm per workpiece rev is {side} the typical "
            f"{low:.1f}–{high:.1f} for m{gear.module:g} {CUTTING[proposal.cut]} ({_row_said(row.module, gear.module)}, "
            f"reference §C){check}"]


def _row_said(row_module: float, module: float) -> str:
    """'the row of m3' for an m3 gear; 'the row up to m3' for an m2.5 gear; 'the last row, m4' beyond it."""
    if row_module == module:
        return f"the row of m{row_module:g}"
    return f"the row up to m{row_module:g}" if row_module > module else f"the last row, m{row_module:g}"


def _speed_notes(gear: Gear, hob: Hob, proposals: dict) -> list[str]:
    tool = TOOLS[tool_of(hob)]
    row = speeds_of(gear)
    if row is None:
        if not (gear.material or "").strip():
            return ["no reference cutting speed range for a gear with no material; check v by hand"]
        return [f"no reference cutting speed range for material {gear.material}: instantiate refuses it; add it "
                "with its speeds (`engine materials import FILE.csv`) or correct the gear's material"]
    low, high = row.ranges[tool_of(hob)]
    notes = [f"{p.cut}: cutting speed {p.cutting_speed:.1f} m/min is {'above' if p.cutting_speed > high else 'below'} "
             f"the typical {low}–{high} for {gear.material} with a {tool} hob (reference §C)"
             for p in proposals.values() if not low <= p.cutting_speed <= high]
    rough, finish = proposals["rough"], proposals["finish"]
    if abs(finish.cutting_speed - rough.cutting_speed) > 0.05 * rough.cutting_speed:
        notes.append(f"finish: its cases suggest v = {finish.cutting_speed:.1f} m/min; the job runs one hob speed, "
                     f"the rough cut's ({rough.cutting_speed:.1f} m/min)")
    return notes


def confirm_job(conn: Connection, job_id: int) -> list[int]:
    """A proven job joins the history: one case per cut kind of its stored cutting data. The database
    decides (confirm_job_cases): only a job the engine made a program for, with cutting data its
    machine can run, becomes a case; runners cannot add cases any other way."""
    try:
        with conn.transaction():
            return scalar(conn.execute("SELECT confirm_job_cases(%s)", (job_id,)))
    except (psycopg.errors.CheckViolation, psycopg.errors.NoDataFound) as error:
        raise EngineError(error.diag.message_primary) from None


def seed_cases(conn: Connection, path: Path = SEED_FILE) -> int:
    """Add the cases of the seed file not yet in the history (same features, cut and source)."""
    path = Path(path)
    if not path.is_file():
        raise EngineError(f"{path} does not exist; give the machining history seed file (columns of cutting_case)")
    file = read_csv_file(path, CASE_KIND)
    rows, problems = [], []
    for line, record in file.rows():
        values = {column.name: file.cell(column, record.get(column.name, ""), line) for column in CASE_KIND.columns}
        problems += [problem for _, problem in values.values() if problem]
        rows.append((line, {name: value if value is not None or name not in ("hob_coating", "source") else ""
                            for name, (value, _) in values.items()}))
    if problems:
        raise CsvError(path, problems, nothing="nothing seeded")
    added = 0
    with conn.transaction():
        for line, case in rows:
            try:
                added += _insert_if_missing(conn, case)
            except (psycopg.errors.DataError, psycopg.errors.IntegrityError) as error:
                raise refuse(path, f"the database refused the case ({str(error).splitlines()[0]})",
                             "correct the row; nothing seeded", line) from None
    return added


MATCH_COLUMNS = (*FEATURE_COLUMNS, "cut", "source")
SEED_COLUMNS = (*MATCH_COLUMNS, *VALUE_COLUMNS)
FIND_CASE = sql.SQL("SELECT 1 FROM cutting_case WHERE {}").format(sql.SQL(" AND ").join(
    sql.SQL("{} IS NOT DISTINCT FROM {}").format(sql.Identifier(c), sql.Placeholder(c)) for c in MATCH_COLUMNS))
SEED_CASE = sql.SQL("INSERT INTO cutting_case ({}) VALUES ({})").format(
    sql.SQL(", ").join(map(sql.Identifier, SEED_COLUMNS)), sql.SQL(", ").join(map(sql.Placeholder, SEED_COLUMNS)))


def _insert_if_missing(conn: Connection, values: dict) -> int:
    # Values go as text: the server parses them into the column types (numeric exactly).
    if conn.execute(FIND_CASE, values).fetchone():
        return 0
    conn.execute(SEED_CASE, values)
    return 1
