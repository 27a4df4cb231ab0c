"""Acceptance tests of issue 14 ("Must show"), from the reference, not from the engine's code.

Programs are made through the public library function (engine.programs.instantiate.instantiate_gear)
and the CLI, for gears, hobs and a machine inserted here, and read with tests/helpers/hobbing_reference.py;
the checks (tests/helpers/hobbing_checks.py) compute every expected number from docs/reference/hobbing.md
§A5, §A7, §B, §C and design notes §7:

* EGON B ratio −h_hob·z0 : z2, helical Z factor −h_gear·360 sinβ/(π mn z2), swivel A = h_hob·γ − h_gear·β,
  tangential Y factor +360 cosγ/(π mn z2), on the DIN machine and transformed by the senses of a
  machine with A, C and Z reversed;
* the program contract (header, G90 G71 G94, G25/G26 + WALIMON, work offset, Y, A=, M3 S, M8/M9,
  EGOFS, EGDEL, M5, M30);
* depth, clearance of the infeed, run-out beyond the other face, §C roughing feed per workpiece
  revolution, and the hob envelope against every unit not being cut.

Case ids name class, hands (gear/hob), hob starts and the job choice, and the machine.
"""
from __future__ import annotations

import uuid

import psycopg
import pytest
from helpers.hobbing_checks import (
    Case,
    Job,
    approach_problems,
    contract_problems,
    coupling_problems,
    depth_problems,
    envelope_problems,
    feed_problems,
)
from helpers.hobbing_machine_checks import all_problems, cycle_time_problems, obstacle_problems, table_speed_problems
from helpers.hobbing_reference import Gear, Hob, Unit, layout_cuttable, lead_angle, read
from helpers.hobbing_reference_gears import (
    DIN,
    MIRROR,
    PAPER_STOCK,
    REVERSED,
    STOCK,
    TOOL_NUMBER,
    cylindrical,
    insert_gear,
    insert_hob,
    insert_machine,
    make_gear,
    make_hob,
    only_hob,
    read_holding,
    read_machine,
)
from helpers.hobbing_reference_programs import HAND_WRITTEN
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from psycopg.conninfo import make_conninfo

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

# ---------------------------------------------------------------- the reader and checks on known programs

@pytest.mark.parametrize("name", sorted(HAND_WRITTEN))
def test_checks_pass_a_hand_computed_correct_program(name):
    text, case, _ = HAND_WRITTEN[name]
    assert all_problems(read(text), case) == []


@pytest.mark.parametrize("name, fault", [(name, fault) for name, (_, _, faults) in sorted(HAND_WRITTEN.items())
                                         for fault in faults])
def test_checks_find_each_planted_fault(name, fault):
    text, case, faults = HAND_WRITTEN[name]
    old, new, check = faults[fault]
    assert old in text, f"fault {fault}: {old!r} not in the program"
    problems = check(read(text.replace(old, new, 1)), case)
    assert problems, f"{check.__name__} missed the fault {fault}: {old!r} → {new!r}"


def test_reader_follows_axes_and_reads_calls():
    text, case, _ = HAND_WRITTEN["spur"]
    nc = read(text)
    g1 = [m for m in nc.moves if m.mode == "G1"]
    assert [(m.start["X"], m.end["X"], m.end["Z"], m.feed) for m in g1] == [(80.0, 62.5, 20.0, 36.0),
                                                                            (62.5, 62.5, -24.0, 25.0)]
    assert nc.calls("EGON") == [(nc.first("EGON"), ("C", "FINE", "B", "-1", "30"))]
    assert nc.after[nc.first("EGON")]["A"] == 1.763 and nc.first("WALIMON") < nc.first("motion")
    assert read("G0 Y=R11\nM1=3 S1=300\nG4 F2").blocks[0].words["Y"] == "R11"
    assert 3 in read("M1=3 S1=300").blocks[0].m and read("G4 F2").moves == []


# ---------------------------------------------------------------- the matrix of cases

JOB_CHOICES = {
    "default": {}, "cuts1": {"cuts": 1}, "cuts2": {"cuts": 2}, "conventional": {"feed_mode": "conventional"},
    "conventional-climb": {"feed_mode": "conventional-climb"}, "no-coolant": {"coolant": False},
    "no-tailstock": {"tailstock": False}, "shift-fixed": {"shift_y": 5.0}, "shift-per-part": {"shift_per_part": 2.5},
    "40Cr-paper-data": {},
}
WORM_CHOICES = ("default", "no-coolant", "no-tailstock")


def matrix() -> dict[str, tuple]:
    """id → (class, gear hand, hob hand, starts, cone, large unit below, worm feed, job choice)."""
    cases = {}

    def add(cls, gear_hand, hob_hand, z0=1, cone=0.0, large_below=True, worm="radial", choice="default"):
        label = {"taper": f"cone{cone:+g}", "duplex": "small-over-large" if large_below else "large-over-small",
                 "worm_wheel": worm}.get(cls, "")
        key = "-".join(p for p in (cls, label, f"gear{gear_hand or '-'}", f"hob{hob_hand}{z0}", choice) if p)
        cases[key] = (cls, gear_hand, hob_hand, z0, cone, large_below, worm, choice)

    for cls, variants in (("spur", [{}]), ("crowned", [{}]), ("taper", [{"cone": 6.5}, {"cone": -6.5}]),
                          ("duplex", [{"large_below": True}, {"large_below": False}]),
                          ("helical", [{}])):
        for variant in variants:
            gear_hands = ("R", "L") if cls == "helical" else (None,)
            for gear_hand in gear_hands:
                for hob_hand in ("R", "L"):
                    add(cls, gear_hand, hob_hand, **variant)
            add(cls, gear_hands[0], "R", z0=3, **variant)
            for choice in JOB_CHOICES:
                if choice != "default":
                    add(cls, gear_hands[0], "R", choice=choice, **variant)
    for worm in ("radial", "tangential"):
        for hand in ("R", "L"):
            add("worm_wheel", hand, hand, worm=worm)
            add("worm_wheel", hand, hand, z0=2, worm=worm)
        for choice in WORM_CHOICES[1:]:
            add("worm_wheel", "R", "R", worm=worm, choice=choice)
    return cases


MATRIX = matrix()
MACHINES = {"din": DIN, "mirror": MIRROR, "reversed": REVERSED}
CASE_IDS = [f"{key}@{machine}" for key in MATRIX for machine in ("din", "mirror")]
# every sense reversed (B and Y too): the coupling and swivel values, for both hands of every class
REVERSED_IDS = [f"{key}@reversed" for key in MATRIX if key.endswith("-default")]


class Bench:
    """One rolled-back connection holding the inserted hobs, gears and mirror machine; each
    program is made once (in a savepoint, rolled back) and kept."""

    def __init__(self, conn):
        self.conn, self.made, self.gear_ids = conn, {}, {}
        insert_machine(conn, MIRROR)
        insert_machine(conn, REVERSED)
        self.machines = {key: read_machine(conn, machine.name) for key, machine in MACHINES.items()}

    def case(self, case_id: str) -> tuple[Case, object, object]:
        if case_id not in self.made:
            self.made[case_id] = self._make(case_id)
        return self.made[case_id]

    def _make(self, case_id: str):
        key, machine_key = case_id.split("@")
        cls, gear_hand, hob_hand, z0, cone, large_below, worm, choice = MATRIX[key]
        worm_wheel = cls == "worm_wheel"
        mn = {"helical": 3, "crowned": 2.5, "worm_wheel": 3}.get(cls, 4 if cls == "duplex" and large_below else 2)
        hob = make_hob(mn, hob_hand, z0, worm_wheel)
        gear = make_gear(cls, gear_hand, hob, cone, large_below)
        choices = dict(JOB_CHOICES[choice], **({"worm_feed": worm} if worm_wheel else {}))
        shift = {"shift-fixed": 5.0, "shift-per-part": "per part"}.get(choice, 0.0)
        case = Case(gear, hob, self.machines[machine_key],
                    Job(choices.get("coolant", True), shift, worm, choices.get("tailstock", True)))
        gear_id = self.gear_ids[case_id] = 9000 + len(self.made)
        with self.conn.transaction(force_rollback=True):
            only_hob(self.conn, insert_hob(self.conn, hob, mn, "worm_wheel" if worm_wheel else "cylindrical"))
            insert_gear(self.conn, gear_id, gear, 0.02 if cls == "crowned" else 0.0,
                        PAPER_STOCK if choice == "40Cr-paper-data" else STOCK)
            try:
                program = instantiate_gear(self.conn, gear_id, machine=case.machine.name, choices=Choices(**choices))
            except Exception as error:          # kept: the test names what went wrong
                return case, None, error
        return case, read(program.text), None


@pytest.fixture(scope="module")
def bench(database_url, database_pool, _seeded_copies):
    """On its own copy of the seeded database, from the pool (the session's database itself cannot
    be copied while `conn` holds a connection to it). Dropped by the pool, behind the tests that follow."""
    name = database_pool.take(_seeded_copies)
    try:
        with psycopg.connect(make_conninfo(database_url, dbname=name)) as connection:
            with connection.transaction(force_rollback=True):
                yield Bench(connection)
    finally:
        database_pool.give_back(name)


def program_of(bench, case_id):
    """The case's program; None when the engine refused a layout the reference shows cannot be cut,
    in one line naming the gear (the right answer there)."""
    case, nc, error = bench.case(case_id)
    if error is None:
        return case, nc
    refusal_due = isinstance(error, EngineError) and not layout_cuttable(case.gear, case.hob, shift=shift_range(case))
    message = str(error)
    if not refusal_due or len(message.splitlines()) != 1 or f"gear {bench.gear_ids[case_id]}" not in message:
        pytest.fail(f"{case_id}: no program, {type(error).__name__}: {error}")
    return case, None


def shift_range(case: Case) -> tuple:
    """Where the job puts the hob's shift (DIN): a fixed position, or for a shift per part anywhere the
    hob's length allows around the centre (the program's own limits are unknown without a program)."""
    if isinstance(case.job.shift, float):
        return case.job.shift, case.job.shift
    return -case.hob.length / 2, case.hob.length / 2


def test_the_issue_duplex_layout_cannot_be_cut_but_the_other_can():
    """The reference check behind accepting a refusal: in the issue's layout (m4, z74 d_a 304 over
    z106 d_a 433.9 at Z−75, 45 mm gap = the hob radius) unit 1's run-out needs the hob centre below
    Z−30, where its tip (and its swivelled ends) reach into unit 2."""
    hob = make_hob(4, "R")
    assert not layout_cuttable(make_gear("duplex", None, hob, large_below=True), hob)
    hob = make_hob(2, "R")
    assert layout_cuttable(make_gear("duplex", None, hob, large_below=False), hob)


def assert_none(problems, case_id):
    assert not problems, f"{case_id}:\n  " + "\n  ".join(problems)


@pytest.mark.parametrize("case_id", CASE_IDS + REVERSED_IDS)
def test_coupling_and_swivel_signs_follow_reference_and_machine(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else coupling_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_program_contract(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else contract_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_last_cut_reaches_full_depth(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else depth_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_infeed_clear_of_blank_and_pass_beyond_other_face(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else approach_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", [c for c in CASE_IDS if not c.startswith("worm_wheel")])
def test_rough_feed_within_reference_maximum_for_module(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else feed_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", [c for c in CASE_IDS if not c.startswith("worm_wheel")])
def test_hob_envelope_never_enters_a_unit_outside_its_cut(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else envelope_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_hob_never_touches_fixture_or_tailstock(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else obstacle_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_table_speed_within_machine_limit_on_every_coupled_move(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else table_speed_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_cycle_time_header_agrees_with_the_moves(bench, case_id):
    case, nc = program_of(bench, case_id)
    assert_none([] if nc is None else cycle_time_problems(nc, case), case_id)


@pytest.mark.parametrize("case_id", [c for c in CASE_IDS if c.endswith("default@din")])
def test_tool_call_before_cutting_and_final_load_position(bench, case_id):
    """Issue 14: T<tool_number> D1 before the first cut; the program ends at the load position the
    machine row declares."""
    case, nc = program_of(bench, case_id)
    if nc is None:
        return
    tool = [b for b in nc.blocks if b.words.get("T") == TOOL_NUMBER and b.words.get("D") == 1]
    assert tool and tool[0].index < nc.first("G1 move"), f"{case_id}: no T{TOOL_NUMBER} D1 before the first G1"
    last, load = nc.moves[-1], case.machine.load
    assert (last.end["X"], last.end["Z"]) == load, \
        f"{case_id}: ends at X{last.end['X']} Z{last.end['Z']}, not the machine's load position X{load[0]} Z{load[1]}"


# ---------------------------------------------------------------- the issue's duplex layout through the CLI

def test_issue_duplex_layout_through_the_cli_programs_safely_or_refuses_in_one_line(run):
    gear = make_gear("duplex", None, make_hob(4, "R"), large_below=True)
    with psycopg.connect(run.url) as conn:
        insert_gear(conn, 9900, gear)
    result = run("instantiate", "--gear", 9900)
    assert result.exit_code in (0, 1), f"exit {result.exit_code}: {result.output}"
    if result.exit_code == 1:
        message = result.stderr.strip()
        assert len(message.splitlines()) == 1 and "gear 9900" in message, message
        return
    nc = read(result.stdout)
    hob_line = next(line for line in nc.lines if line.startswith("; HOB "))
    fields = dict(part.split("=") for part in hob_line.split()[3:])
    with psycopg.connect(run.url) as conn:
        length, hand = conn.execute("SELECT length, hand FROM hob WHERE id = %s", (hob_line.split()[2],)).fetchone()
        case = Case(gear, Hob(int(fields["z0"]), float(fields["da0"]), hand, float(length)),
                    read_machine(conn, "hobber-840d"))
    assert_none(envelope_problems(nc, case) + approach_problems(nc, case) + obstacle_problems(nc, case), "issue duplex")


# ---------------------------------------------------------------- random valid gears of every class

CLASSES = ("spur", "helical", "taper", "crowned", "worm_wheel-radial", "worm_wheel-tangential", "duplex")
MODULES = (1, 1.5, 2, 2.5, 3, 4)


@st.composite
def random_case(draw, kind: str):
    cls, _, worm = kind.partition("-")
    mn = draw(st.sampled_from(MODULES if cls != "worm_wheel" else (3,)))
    hob_hand = draw(st.sampled_from("RL"))
    hob = make_hob(mn, hob_hand, draw(st.sampled_from((1, 2, 3) if cls != "worm_wheel" else (1, 2))),
                   cls == "worm_wheel")
    z2 = draw(st.integers(14, 110))
    b = draw(st.floats(5, 60).map(lambda v: round(v, 1)))
    beta = draw(st.sampled_from((0.0, 8.0, 15.0, 22.5))) if cls in ("helical", "taper", "crowned") else 0.0
    beta = beta or (12.0 if cls == "helical" else 0.0)
    hand = draw(st.sampled_from("RL")) if beta else None
    if cls == "worm_wheel":
        beta, hand = round(lead_angle(mn, hob), 3), hob_hand
    x = draw(st.floats(-0.3, 0.5).map(lambda v: round(v, 2)))
    units = [Unit(z2, b, *cylindrical(mn, z2, beta, x))]
    if cls == "duplex":
        z2b, b2 = draw(st.integers(14, 110)), draw(st.floats(5, 40).map(lambda v: round(v, 1)))
        gap = draw(st.floats(5, 80).map(lambda v: round(v, 1)))
        units.append(Unit(z2b, b2, *cylindrical(mn, z2b), z_top=-(b + gap)))
    cone = draw(st.floats(0.5, 10).map(lambda v: round(v, 2))) * draw(st.sampled_from((1, -1)))
    gear = Gear(cls, mn, beta, hand, tuple(units), cone=cone if cls == "taper" else 0.0)
    choice = dict(draw(st.sampled_from(list(JOB_CHOICES.values()))) if cls != "worm_wheel" else
                  draw(st.sampled_from([JOB_CHOICES[c] for c in WORM_CHOICES])))
    if worm:
        choice["worm_feed"] = worm
    crowning = draw(st.floats(0.005, 0.05).map(lambda v: round(v, 3))) if cls == "crowned" else 0.0
    return gear, hob, choice, crowning, draw(st.sampled_from((STOCK, PAPER_STOCK, ("20CrMnTi", 180, 7))))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@pytest.mark.parametrize("kind", [pytest.param(kind, marks=() if kind == "spur" else pytest.mark.slow)
                                  for kind in CLASSES])    # 30 random gears each: spur alone in the fast subset
@settings(max_examples=30, deadline=None, database=None, phases=(Phase.explicit, Phase.generate),
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_random_valid_gears_make_a_correct_program_or_a_one_line_refusal(conn, kind, data):
    gear, hob, choice, crowning, stock = data.draw(random_case(kind))
    gear_id = 9400 + uuid.uuid4().int % 400
    worm_wheel = gear.gear_class == "worm_wheel"
    with conn.transaction(force_rollback=True):
        only_hob(conn, insert_hob(conn, hob, gear.mn, "worm_wheel" if worm_wheel else "cylindrical"))
        insert_gear(conn, gear_id, gear, crowning, stock)
        try:
            program = instantiate_gear(conn, gear_id, choices=Choices(**choice))
        except EngineError as refusal:
            message = str(refusal)
            assert len(message.splitlines()) == 1, f"refusal of more than one line: {message!r}"
            if gear.gear_class == "duplex":
                assert f"gear {gear_id}" in message, f"a duplex refusal must name the gear: {message!r}"
            return
    shift = {5.0: 5.0}.get(choice.get("shift_y"), "per part" if choice.get("shift_per_part") else 0.0)
    case = Case(gear, hob, read_machine(conn, DIN.name), Job(choice.get("coolant", True), shift,
                                                             choice.get("worm_feed", "radial"),
                                                             choice.get("tailstock", True)),
                read_holding(conn, program.text))
    problems = all_problems(read(program.text), case)
    assert not problems, f"{gear} {hob} {choice}:\n  " + "\n  ".join(problems) + "\n" + program.text


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("x", [-0.3, 0.0, 0.5])
def test_a_taper_growing_downward_keeps_its_rapids_clear_of_the_large_end(conn, x):
    """Once drawn by the random test above (every x and stock failed): m4, z96, β 8° R, b 56.9,
    δ −5.83°, hob 2 starts d_a0 90 R, shift per part. `G0 Z35.022` between the cuts, at the retract
    X, ran the hob into the blank's bottom face, d_a2/2 + b·tan|δ| = 5.81 mm larger in radius."""
    gear = Gear("taper", 4, 8.0, "R", (Unit(96, 56.9, *cylindrical(4, 96, 8.0, x)),), cone=-5.83)
    hob, choice = make_hob(4, "R", 2), {"shift_per_part": 2.5}
    with conn.transaction(force_rollback=True):
        only_hob(conn, insert_hob(conn, hob, gear.mn, "cylindrical"))
        insert_gear(conn, 9399, gear, 0.0, STOCK)
        program = instantiate_gear(conn, 9399, choices=Choices(**choice))
    case = Case(gear, hob, read_machine(conn, DIN.name), Job(True, "per part", "radial", True))
    assert all_problems(read(program.text), case) == []
