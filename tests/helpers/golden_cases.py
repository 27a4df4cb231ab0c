"""The cases of the golden programs in tests/golden/: every seeded gear under each set of job
choices, and turning jobs from the real Emco drawings and from drawings made in the tests, in
both lathe dialects.

Golden files are a regression guard, not a proof of correctness (the physics and the 840D
contract are tested from the reference formulas elsewhere): they were written by
tests/golden/make_golden.py before the evaluator changes of issue 12, so that a change of
evaluator that alters any emitted byte fails. A change that is meant to alter programs (a
corrected model, issue 14) writes them again with that script, and the diff shows every line
it changed."""
from __future__ import annotations

import re
from pathlib import Path

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear
from engine.programs.remake import instantiate_job
from engine.turning.job_params import ProfileOptions
from engine.verifier.grammar import HOBBING_FANUC
from importers.dxf import import_dxf

GOLDEN = Path(__file__).resolve().parents[1] / "golden"

HOBBING_GEARS = (42, 43, 44, 45, 46, 47, 50, 51, 53, 54)   # seed_templates/gears.csv: every class
CHOICE_SETS = {   # name -> (process choices, overrides)
    "default": ({}, {}),
    "two-cuts": ({"cuts": 2}, {}),
    "single-cut": ({"cuts": 1}, {}),
    "dry-no-tailstock": ({"coolant": False, "tailstock": False}, {}),
    "conventional": ({"feed_mode": "conventional"}, {}),
    "conventional-climb": ({"cuts": 2, "feed_mode": "conventional-climb"}, {}),
    "shift-y": ({"shift_y": 5.0}, {}),
    "shift-per-part": ({"shift_per_part": 0.5}, {}),
    "tangential": ({"worm_feed": "tangential"}, {}),
    "hob-speed": ({}, {"hob_speed": 300}),
}

# (name, drawing: "emco:<file>" from the real files or a maker of test_dxf_read/test_turning_jobs,
#  ProfileOptions fields and the program name if given, alternate). The Emco file names make
#  program names longer than 840D's 24 characters, so those cases name their programs.
TURNING_CASES = (
    ("emco-neg", "emco:emco_lathe_testNegDXF_R14.dxf", {"rough_depth": 1.0, "program_name": "EMCO_TESTNEGDXF_R14"},
     None),
    ("emco-g02", "emco:emco_lathe_testg02hemisphere_R14.dxf",
     {"rough_depth": 1.0, "program_name": "EMCO_TESTG02HEMISPHERE"}, None),
    ("emco-g03", "emco:emco_lathe_testg03hemisphere_R14.dxf",
     {"rough_depth": 1.0, "allowance": 0.2, "program_name": "EMCO_TESTG03HEMISPHERE"}, None),
    ("seed-part", "seed_drawing", {}, None),
    ("shaft-profile", "profile_only_drawing", {"rough_depth": 1.5, "allowance": 0.3}, None),
    ("wheel-alternate", "two_rough_layers", {}, [1, 2]),
)
LATHES = ("lathe-iso", "lathe-840d")


# The Fanuc hobber's goldens (issue 30): the same gears and choice sets on hobber-fanuc, the
# coupling rendered as G81/G80 by the same class templates. While the Fanuc grammar of this tree
# does not read the agreed tailstock M20/M21 (a grammar change of its own), they are made without
# the tailstock (False); once it does, with each set's own choice (None): write them again then.
FANUC_MACHINE = "hobber-fanuc"
FANUC_TAILSTOCK: bool | None = None if {20, 21} <= HOBBING_FANUC.m_codes.keys() else False

WORM_WHEELS = (53,)   # no axial pass: their cases leave out the feed modes (refused for them)


def hobbing_cases() -> list[tuple[int, str]]:
    return [(gear_id, choice_set) for gear_id in HOBBING_GEARS for choice_set in CHOICE_SETS
            if not (gear_id in WORM_WHEELS and "feed_mode" in CHOICE_SETS[choice_set][0])]


def fanuc_hobbing_file(gear_id: int, choice_set: str) -> Path:
    return GOLDEN / "hobbing_fanuc" / f"GEAR{gear_id}_{choice_set}.NC"


def turning_cases() -> list[tuple[str, str]]:
    return [(case[0], lathe) for case in TURNING_CASES for lathe in LATHES]


def hobbing_file(gear_id: int, choice_set: str) -> Path:
    return GOLDEN / "hobbing" / f"GEAR{gear_id}_{choice_set}.MPF"


def turning_file(name: str, lathe: str) -> Path:
    return GOLDEN / "turning" / f"{name}_{lathe}.NC"


def without_iso_program_number(text: str) -> str:
    """An ISO lathe program's number (`O0138`) is drawn from a database sequence, so it depends on
    how many turning jobs the database made before; compared as `O####`. The job's parameters hold
    that number (in both dialects), so the lineage line's INPUT hash is compared as `INPUT ########`."""
    text = re.sub(r"^O\d{4}\b", "O####", text, count=1, flags=re.MULTILINE)
    return re.sub(r"^([;(] ?PROGRAM .* INPUT )[0-9a-f]{8}", r"\1########", text, count=1, flags=re.MULTILINE)


def with_program_id_masked(text: str) -> str:
    """The lineage line's program id (`; PROGRAM 812 TEMPLATE …`) is drawn from a database sequence
    that rolled-back tests advance too, so it is written as `PROGRAM #`; the template version and
    the hashes of the line stay, so a change of either still fails."""
    return re.sub(r"^([;(] ?PROGRAM )\d+(?= TEMPLATE )", r"\1#", text, count=1, flags=re.MULTILINE)


def hobbing_text(conn, gear_id: int, choice_set: str, machine: str | None = None) -> str:
    """The program of the gear under the choice set on `machine` (None: the default 840D hobber;
    FANUC_MACHINE: without the tailstock, FANUC_TAILSTOCK), its program id masked, or the one-line
    refusal."""
    choices, overrides = CHOICE_SETS[choice_set]
    if machine == FANUC_MACHINE and FANUC_TAILSTOCK is not None:
        choices = {**choices, "tailstock": FANUC_TAILSTOCK}
    try:
        return with_program_id_masked(
            instantiate_gear(conn, gear_id, machine=machine, choices=Choices(**choices), overrides=overrides).text)
    except EngineError as error:
        return f"refused: {error}\n"


def turning_text(conn, folder: Path, name: str, lathe: str) -> str:
    """The program of the turning case on the lathe (its program id masked), or the one-line refusal."""
    _, maker, options, alternate = next(case for case in TURNING_CASES if case[0] == name)
    options = dict(options)
    program_name = options.pop("program_name", None)
    path = _drawing(folder, name, maker)
    try:
        report = import_dxf(conn, path, lathe, ProfileOptions(**options), alternate, program_name)
        return with_program_id_masked(instantiate_job(conn, report.job_id).text)
    except EngineError as error:
        return f"refused: {error}\n"


def _drawing(folder: Path, name: str, maker: str) -> Path:
    """The drawing of a case: a real file as it is, or one made by the tests' own makers under
    a fixed name (the name is printed in the program's header)."""
    from helpers.drawings import DXF, seed_drawing
    from helpers.drawn_parts import profile_only_drawing, two_rough_layers

    if maker.startswith("emco:"):
        return DXF / maker.removeprefix("emco:")
    makers = {"seed_drawing": seed_drawing, "profile_only_drawing": profile_only_drawing,
              "two_rough_layers": two_rough_layers}
    path = folder / f"{name}.dxf"
    makers[maker](path)
    return path
