"""The machining history, for the nearest-case search of every instantiation.

Plain Python, no pandas or numpy: a single `engine instantiate` must start fast (numpy's
import alone is 70 ms), a batch asks once per gear kind, and a shop's history is hundreds of
cases, not millions; `engine.gears.cases` builds the tables people read on top.
Distance d = Σ weight·|case − query|/scale over numeric features + Σ weight·[case ≠ query]
over categorical ones; a value missing on either side counts as a full mismatch (1).
Cases transfer to this gear and hob through what carries over between hobs and gears: the
cutting speed v = π·d_a0·n0/1000 and the feeds per workpiece revolution f = v_f/(n0·z0/z2)
(docs/reference/hobbing.md §B4, §B5).
"""
from __future__ import annotations

import heapq
import math
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..notes import Note, replaced_head
from .cutting_data import (
    FEED_EPSILON,
    RADIAL_TO_AXIAL,
    CuttingData,
    default_cutting_data,
    feed_limit,
    hob_speed,
    per_minute,
)
from .speed_table import TOOLS, most_hob_speed, speed_range, speeds_of, tool_of

if TYPE_CHECKING:
    from ..db.connection import Connection

CUT_KINDS = ("rough", "finish")
CUT_KINDS_BY_COUNT = {1: ("rough",), 2: ("rough", "finish")}   # a single cut is a rough cut, as in the paper
FEED_BOUNDED = ", feed bounded"   # a proposal's source once bounded_proposal lowered its axial feed
SINGLE_CUT = "single cut"         # what a note of a job of one cut is labelled (its data are the rough kind's)
EXACT = 1e-9   # a case this close is the same situation: taken as is

# (feature, kind, scale, weight)
DISTANCE_FEATURES = (
    ("module", "numeric", 1.0, 3.0),            # chip size and tooth depth follow the module
    ("material", "categorical", None, 2.0),     # each material has its own speed range (§C)
    ("hardness", "numeric", 50.0, 1.0),         # HB; 50 HB spans a heat-treatment state
    ("quality_grade", "numeric", 2.0, 0.5),
    ("hob_material", "categorical", None, 2.0),  # HSS or carbide: a different speed range
    ("hob_coating", "categorical", None, 1.5),   # coated HSS runs about twice as fast (§C)
    ("hob_starts", "numeric", 1.0, 1.0),        # multi-start hobs: lower feed or speed (§C)
    ("hob_tip_diameter", "numeric", 20.0, 0.5),  # mostly carried over by the transfer through v
    ("teeth", "numeric", 20.0, 0.25),           # carried over by feeds per workpiece revolution
    ("cut", "categorical", None, 3.0),          # candidates are of the same cut kind anyway
)
CASE_COLUMNS = ("id", "module", "teeth", "material", "hardness", "quality_grade", "hob_material",
                "hob_coating", "hob_starts", "hob_tip_diameter", "cut", "hob_speed", "axial_feed",
                "radial_feed", "source", "job_id", "created_at")
LOAD_CASES = f"SELECT {', '.join(CASE_COLUMNS)} FROM cutting_case ORDER BY id"   # static column list


class KindProposal(msgspec.Struct, frozen=True):
    """The cutting speed and feeds proposed for one cut kind (rough, finish), and the cases they came from."""
    cut: str
    cutting_speed: float     # m/min
    axial_feed: float        # mm per workpiece revolution
    radial_feed: float       # mm per workpiece revolution
    source: str
    case_ids: tuple = ()     # the cases it came from


def query_of(gear, hob, cut: str) -> dict:
    return {"module": gear.module, "teeth": gear.teeth, "material": gear.material, "hardness": gear.hardness,
            "quality_grade": gear.quality_grade, "hob_material": hob.material, "hob_coating": hob.coating,
            "hob_starts": hob.starts, "hob_tip_diameter": hob.tip_diameter, "cut": cut}


class CaseBase:
    """The history read once, per cut kind: each case's features and transferred values."""

    def __init__(self, records: list[dict]):
        self.records = records
        self.of_kind = {cut: [_Case.of(position, record) for position, record in enumerate(records)
                              if record["cut"] == cut] for cut in CUT_KINDS}

    @classmethod
    def load(cls, conn: Connection) -> CaseBase:
        rows = conn.execute(LOAD_CASES).fetchall()
        return cls([{name: _plain(value) for name, value in zip(CASE_COLUMNS, row)} for row in rows])

    def nearest(self, query: dict, top: int) -> list[tuple[float, _Case]]:
        """(distance, case) of the `top` nearest cases of the query's cut kind, nearest first
        (ties by case id)."""
        wanted = _features(query)
        ranked = ((distance(case.features, wanted), case) for case in self.of_kind.get(query["cut"], []))
        return heapq.nsmallest(top, ranked, key=lambda found: (found[0], found[1].id))

    def propose(self, query: dict, top: int, defaults: CuttingData) -> tuple[KindProposal, list]:
        """Inverse-distance weighted mean of the transferred values; exact matches as they are."""
        cut = query["cut"]
        found = self.nearest(query, top)
        if not found:
            axial = defaults.axial_feed_rough if cut == "rough" else defaults.axial_feed_finish
            radial = defaults.radial_feed if cut == "rough" else RADIAL_TO_AXIAL * axial
            return KindProposal(cut, defaults.cutting_speed, axial, radial,
                                f"{cut}: no cases, {defaults.source}"), found
        exact = [(1.0, case) for d, case in found if d <= EXACT]
        weighted = exact or [(1.0 / d, case) for d, case in found]
        total = sum(weight for weight, _ in weighted)
        ids = tuple(case.id for _, case in weighted)

        def mean(name):
            return sum(weight * getattr(case, name) for weight, case in weighted) / total
        how = "as is" if exact else "inverse-distance weighted"
        source = f"{cut}: case{'s' if len(ids) > 1 else ''} {', '.join(f'#{i}' for i in ids)} {how}"
        proposal = KindProposal(cut, mean("cutting_speed"), mean("axial_per_rev"), mean("radial_per_rev"), source, ids)
        return proposal, found

    def cutting_data(self, gear, hob, machine, top: int = 3) -> tuple[CuttingData, dict, dict]:
        """(cutting data, proposal per cut kind, the nearest (distance, case) per cut kind). The job
        runs one hob speed: the rough cut's, as a single cut is a rough cut."""
        if top < 1:
            raise EngineError(f"top {top}: ask for at least 1 case per cut kind")
        defaults = default_cutting_data(gear.module, gear.material, bool(hob.coating), hob.tip_diameter,
                                        machine.spindle_max, speeds_of(gear))
        found = {cut: self.propose(query_of(gear, hob, cut), top, defaults) for cut in CUT_KINDS}
        bounded = {cut: bounded_proposal(proposal, gear, hob) for cut, (proposal, _) in found.items()}
        proposals = {cut: proposal for cut, (proposal, _) in bounded.items()}
        rough, finish = proposals["rough"], proposals["finish"]
        speed, speed_note = bounded_hob_speed(gear, hob, rough.cutting_speed, machine.spindle_max)
        notes = tuple(note for _, note in bounded.values() if note) + ((speed_note,) if speed_note else ())
        v = rough.cutting_speed if speed_note is None else math.pi * hob.tip_diameter * speed / 1000
        cutting = CuttingData(v, speed, rough.axial_feed, finish.axial_feed, rough.radial_feed,
                              "; ".join(p.source for p in proposals.values()), finish.radial_feed, notes)
        return cutting, proposals, {cut: nearest for cut, (_, nearest) in found.items()}


def bounded_hob_speed(gear, hob, cutting_speed: float, spindle_max: float) -> tuple[int, str | None]:
    """n0 for the proposed v (§B4), at most the §C upper end for the gear's material and the hob's
    material and coating (engine.gears.speed_table: the simulation refuses a faster hob), and the
    one-line note when it was lowered. The note starts with "rough:" (a single cut is a rough cut)."""
    speed = hob_speed(cutting_speed, hob.tip_diameter, spindle_max)
    most = most_hob_speed(gear, hob)
    if speed <= most:
        return speed, None
    return most, Note(f"rough: hob speed {speed} r/min (v {cutting_speed:.1f} m/min) bounded to {most} r/min, "
                  f"the upper end of reference §C for {gear.material or 'an unlisted material'} with a "
                  f"{TOOLS[tool_of(hob)]} hob ({speed_range(gear, hob)[1]:g} m/min)", "hob speed bounded")


def bounded_proposal(proposal: KindProposal, gear, hob) -> tuple[KindProposal, str | None]:
    """The proposal with its axial feed at most the maximum for the gear and hob (the §C table
    for the module, and the chip-thickness bound of Hoffmeister's formula, §C1:
    cutting_data.feed_limit), and the one-line note when it was lowered. The radial feed is
    scaled by the same factor: it came from the same cases, and a feed whose definition is
    suspect (the paper's, §D) is suspect on both axes."""
    limit, why = feed_limit(gear, hob, proposal.cut)
    if proposal.axial_feed <= limit + FEED_EPSILON:
        return proposal, None
    factor = limit / proposal.axial_feed
    lowered = KindProposal(proposal.cut, proposal.cutting_speed, limit, proposal.radial_feed * factor,
                           f"{proposal.source}{FEED_BOUNDED}", proposal.case_ids)
    return lowered, Note(f"{proposal.cut}: axial feed {proposal.axial_feed:.2f} mm per workpiece rev "
                         f"({proposal.source}) bounded to {limit:.2f}, the {why}; radial feed scaled alike to "
                         f"{lowered.radial_feed:.2f}", "feed bounded")


class _Case(msgspec.Struct, frozen=True):
    """A cutting case of the history as the nearest-neighbour search reads it: its features and per-revolution feeds."""
    position: int            # in CaseBase.records
    id: int
    features: tuple          # in DISTANCE_FEATURES order: floats, casefolded text, None when missing
    cutting_speed: float     # m/min
    axial_per_rev: float     # mm per workpiece revolution
    radial_per_rev: float

    @classmethod
    def of(cls, position: int, r: dict) -> _Case:
        table_speed = r["hob_speed"] * r["hob_starts"] / r["teeth"]
        return cls(position, r["id"], _features(r), math.pi * r["hob_tip_diameter"] * r["hob_speed"] / 1000,
                   r["axial_feed"] / table_speed, r["radial_feed"] / table_speed)


def _features(values: dict) -> tuple:
    def plain(value, kind):
        if value is None:
            return None
        return float(value) if kind == "numeric" else str(value).casefold()
    return tuple(plain(values[name], kind) for name, kind, _, _ in DISTANCE_FEATURES)


def distance(case: tuple, query: tuple) -> float:
    total = 0.0
    for (_, kind, scale, weight), have, want in zip(DISTANCE_FEATURES, case, query):
        if have is None or want is None:
            total += weight
        elif kind == "numeric":
            total += weight * abs(have - want) / scale
        elif have != want:
            total += weight
    return total


def _plain(value):
    """numeric columns arrive as Decimal; the search computes in float."""
    from decimal import Decimal

    return float(value) if isinstance(value, Decimal) else value


def feeds_per_rev(cutting: CuttingData, cut: str) -> tuple[float, float]:
    if cut == "rough":
        return cutting.axial_feed_rough, cutting.radial_feed
    if cut == "finish":
        return cutting.axial_feed_finish, cutting.finish_radial_feed
    raise EngineError(f"cut kind {cut!r} is not one of {', '.join(CUT_KINDS)}")


def feeds_per_minute(cutting: CuttingData, gear, hob, cut: str) -> dict:
    """v_f = f·n0·z0/z2 in mm/min, to 0.1 as the program writes it (§B5)."""
    axial, radial = feeds_per_rev(cutting, cut)
    return {name: round(per_minute(feed, cutting.hob_speed, hob.starts, gear.teeth), 1)
            for name, feed in (("axial_feed", axial), ("radial_feed", radial))}


def job_cutting_record(cutting: CuttingData, gear, hob, cut_kinds, case_ids) -> dict:
    """What job.cutting holds: the job's cuts only (a single-cut job is a rough cut), feeds in mm/min."""
    record = {"source": cutting.source, "hob_speed": cutting.hob_speed,
              "cutting_speed": round(cutting.cutting_speed, 1), "case_ids": [int(i) for i in case_ids]}
    if cutting.notes:
        record["notes"] = list(cutting.notes)
    return record | {cut: feeds_per_minute(cutting, gear, hob, cut) for cut in cut_kinds}


def single_cut_labels(notes, cut_count: int) -> list[str]:
    """The notes of a job of `cut_count` cuts: a single cut's (cut with the rough kind's data,
    CUT_KINDS_BY_COUNT) labelled "single cut:", not "rough:" (there is no finish after it)."""
    if cut_count != 1:
        return list(notes)
    return [replaced_head(note, "rough:", f"{SINGLE_CUT}:") for note in notes]
