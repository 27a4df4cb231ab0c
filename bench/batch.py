"""Batch throughput: `instantiate_gears` (the library path behind `engine instantiate --gears`)
over 10,000 gears stored in PostgreSQL, against a plain Jinja2 pipeline that reads the same
gear rows, computes the same jobs with the same model, hob and cutting-data code (the Planner's
own methods: case-based cutting data, cached per gear kind), renders the same lines from
bench/jinja/*.j2 and stores jobs (cutting data included) and programs with the same COPY statements.
Repetitions alternate; stored jobs/programs are deleted (and vacuumed) before each one.
Targets: ours/Jinja2 >= 1 and ours >= 5,000 programs/s.

    python bench/batch.py [--reps 3] [--count 10000] [--profile] [--database-url URL]

Exit status 0 also when a target is missed (a benchmark reports, it does not fail); 1 when
the Jinja2 templates do not produce our programs line for line (the comparison would be
meaningless) or a pipeline fails.
"""
from __future__ import annotations

import argparse
import json
import random
import shutil
import subprocess
import sys
import time
from decimal import Decimal
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import add_database_argument, bench_database, delete_programs, median, parse_arguments, verdict  # noqa: E402

from engine.errors import EngineError  # noqa: E402
from engine.gears.case_base import CUT_KINDS_BY_COUNT, job_cutting_record  # noqa: E402
from engine.gears.feed_marks import bounded_for_marks  # noqa: E402
from engine.gears.hob_matching import choose_hob  # noqa: E402
from engine.gears.holding_matching import choose_holding  # noqa: E402
from engine.hobbing.choices import Choices  # noqa: E402
from engine.programs.instantiate import Planner, check_machine_fits, check_speeds  # noqa: E402
from engine.verifier import verify_program  # noqa: E402

FIRST_ID = 100_000
TARGET_RATE = 5_000          # programs/s
TARGET_RATIO = 1.0           # ours / Jinja2
TARGET_WORKERS_RATIO = 1.7   # --workers 2 / one worker (issue 12)
SAMPLE = 50                  # gears whose Jinja2 output is compared line by line before timing
VARIANT_SAMPLE = 12          # of those, gears also compared under each process-choice variant
# Process choices the batch itself does not use (it runs the defaults: climb, tailstock, no
# shift, coolant): the equality check also covers the template rows they switch on.
CHOICE_VARIANTS = (Choices(feed_mode="conventional-climb", cuts=2), Choices(feed_mode="conventional"),
                   Choices(tailstock=False, coolant=False), Choices(shift_y=4.0),
                   Choices(shift_per_part=1.3))
RANDOM_SEED = 20261122
WARMUP_GEARS = 300           # untimed run of each pipeline first (the Planner's caches live one run)
PROFILE_GEARS = 1_000        # --profile: phases and cProfile over the batch's first gears

MATERIALS = ("45", "C45", "20CrMnTi", "40Cr")   # the rows of engine.gears.cutting_data.CUTTING_SPEED
# (C45 has no case in seed_templates/cases.csv: its nearest cases differ in material)
# Seeded hobs (seed_templates/hobs.csv): module -> (hands, best accuracy class). Grade <= 7
# needs an AA hob (engine.gears.hob_matching.REQUIRED_CLASS_BY_GRADE): only m 2, 2.5, 3 have one.
MODULES_BY_GRADE = {6: ("2", "2.5", "3"), 7: ("2", "2.5", "3"), 8: ("1.5", "2", "2.5", "3", "4")}
LEFT_HAND_HOB_MODULES = {"2", "3"}               # A-class left-hand hobs (grade 8 only)

GEAR_COLUMNS = ("id", "gear_class", "module", "teeth", "pressure_angle", "helix_angle", "hand", "face_width",
                "tip_diameter", "root_diameter", "cone_angle", "crowning", "material", "hardness",
                "quality_grade", "quantity")

# Which template row emits each line of the standard code (seed_templates/classes/*.csv, same
# ids in both classes) and the p_emit condition that decides it: the Jinja2 pipeline stores
# row_ids like the decision table does (program.row_ids is NOT NULL).
ROW_IDS = ((100, None), (200, None), (300, None), (400, None), (500, None), (510, "fixture"), (600, None),
           (650, None), (660, "floor"), (700, None),
           (705, "allowance"), (800, None), (810, None), (900, None), (1000, None), (1100, None),
           (1120, "door_close"), (1150, None), (1200, "tailstock"), (1250, "no_load_position"),
           (1251, "load_position"), (1252, "load_position"), (1300, None),
           (1310, "shift_fixed"), (1320, "shift_per_part"), (1330, "shift_per_part"), (1340, "shift_per_part"),
           (1350, "shift_per_part"), (1360, "shift_per_part"), (1370, "orient"), (1400, None), (1500, None),
           (1700, None), (1800, "coolant"),
           (1900, "cut1"), (2000, "cut1"), (2050, "cut1"), (2100, "cut1"), (2200, "cut1"), (2300, "cut1"),
           (2400, "cut2"), (2500, "cut2"), (2550, "cut2"), (2600, "cut2"), (2700, "cut2"), (2800, "cut2"),
           (2900, "coolant"), (3000, None), (3050, None), (3100, None), (3140, "load_position"),
           (3145, "load_position"), (3150, "tailstock"), (3170, "door_open"), (3200, None))

# Same id allocation as engine.programs.storage; the COPY statements are engine.programs.storage's own.
NEXT_IDS = "SELECT nextval(%s::regclass) FROM generate_series(1, %s)"


# --- the data ------------------------------------------------------------------------------

def generate_gears(first: int, count: int) -> list[tuple]:
    """Plausible spur and helical gears the seeded hob library and hobber-840d can cut."""
    from engine.gears.gear_import import derived_diameters

    rng = random.Random(RANDOM_SEED)
    thousandth = Decimal("0.001")
    rows = []
    for index in range(count):
        grade = rng.choice((6, 7, 8, 8))
        module_text = rng.choice(MODULES_BY_GRADE[grade])
        module = Decimal(module_text)
        teeth = rng.randint(17, 80)
        if index % 2:
            gear_class, beta = "helical", Decimal(rng.choice((15, 20)))
            hands = ("R", "L") if grade == 8 and module_text in LEFT_HAND_HOB_MODULES else ("R",)
            hand = rng.choice(hands)
        else:
            gear_class, beta, hand = "spur", Decimal(0), None
        tip, root = derived_diameters(module, teeth, beta)
        rows.append((first + index, gear_class, module, teeth, Decimal(20), beta, hand, Decimal(rng.randint(10, 40)),
                     tip.quantize(thousandth), root.quantize(thousandth), None, None, rng.choice(MATERIALS),
                     Decimal(rng.randint(170, 280)), grade, rng.randint(1, 200)))
    return rows


def insert_gears(conn, rows: list[tuple]) -> None:
    with conn.cursor().copy(f"COPY gear ({', '.join(GEAR_COLUMNS)}) FROM STDIN") as copy:
        for row in rows:
            copy.write_row(row)
    conn.commit()


def clear_jobs(conn) -> None:
    """Empty job and program before a run. DELETE and VACUUM, not TRUNCATE: cutting_case.job_id
    references job, and TRUNCATE would have to empty the case base with it."""
    delete_programs(conn)
    conn.execute("DELETE FROM job")
    conn.commit()
    conn.autocommit = True
    try:
        conn.execute("VACUUM job, program")
    finally:
        conn.autocommit = False


# --- our path ------------------------------------------------------------------------------

def run_ours(conn, first: int, last: int, workers: int = 1) -> tuple[float, int]:
    """Each run starts with no compiled template and no remembered row outcome, as a new
    `engine instantiate --gears` process does."""
    from engine.programs.instantiate import instantiate_gears
    from engine.programs.options import RunMode
    from engine.templates import decision_table

    decision_table._CACHE.clear()
    start = time.perf_counter()
    programs = instantiate_gears(conn, first, last, mode=RunMode(workers=workers))
    conn.commit()
    return time.perf_counter() - start, len(programs)


# --- the plain Jinja2 pipeline -------------------------------------------------------------

def jinja_environment():
    import jinja2

    environment = jinja2.Environment(loader=jinja2.FileSystemLoader(HERE / "jinja"), autoescape=False,
                                     trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
                                     undefined=jinja2.StrictUndefined, auto_reload=False)
    return environment


class JinjaPipeline:
    """Planner.plan with Jinja2 in place of the decision table, then the same COPY storage."""

    def __init__(self, environment, check: bool = True):
        self.environment = environment
        self.check = check
        self._row_ids: dict[tuple, list[int]] = {}

    def row_ids(self, params: dict, module_params: dict) -> list[int]:
        flags = {"tailstock": bool(params["tailstock"]), "allowance": params["allowance"] > 0,
                 "shift_fixed": params["shift_per_part"] == 0, "shift_per_part": params["shift_per_part"] > 0,
                 "coolant": bool(params["coolant"]), "orient": bool(params["orient_before_coupling"]),
                 "door_close": params["door_close_m"] > 0, "door_open": params["door_open_m"] > 0,
                 "load_position": bool(params["load_position"]), "no_load_position": not params["load_position"],
                 "fixture": params["fixture_id"] != "", "floor": params["floor_to_floor"] > 0,
                 "cut1": bool(module_params["cutmotion:1"]["cut_on"]),
                 "cut2": bool(module_params["cutmotion:2"]["cut_on"])}
        key = tuple(flags.values())
        found = self._row_ids.get(key)
        if found is None:
            found = self._row_ids[key] = [row for row, condition in ROW_IDS if condition is None or flags[condition]]
        return found

    def plan(self, planner: Planner, gear, templates: dict) -> tuple:
        """Planner.plan step for step (same calls, same order), rendering instead of run_template."""
        machine = planner.machine
        check_machine_fits(gear, machine)
        model = planner.model(gear.gear_class)
        hob = choose_hob(gear, planner.hobs, purpose=model.hob_purpose,
                         shift_travel=model.shift_travel(planner.choices)).hob
        holding = choose_holding(gear, hob, machine, planner.holdings, planner.choices.fixture).holding
        cutting, case_ids = planner.cutting_data(gear, hob)
        cutting = bounded_for_marks(cutting, gear, hob, planner.choices.cut_count(gear.module),
                                    planner.choices.allowance, frozenset())
        job = model.job(gear, gear.gear_class, hob, machine, cutting, planner.choices)
        check_speeds(gear, hob.starts, cutting.hob_speed, machine)
        jinja_template, version, template_hash = templates[gear.gear_class]
        params, module_params = {**job.params, "fixture_id": holding.id if holding else ""}, job.module_params
        text = jinja_template.render({**params, "template_version": version, "module_params": module_params})
        lines = text.splitlines()
        name = str(params.get("program_name", f"JOB_{gear.id}"))
        if self.check:
            verify_program(lines, machine, name)
        kinds = CUT_KINDS_BY_COUNT[planner.choices.cut_count(gear.module)]
        record = job_cutting_record(cutting.of_cuts(kinds), gear, hob, kinds, case_ids)
        return (gear.id, gear.gear_class, machine.name, hob.id, params, module_params, version, template_hash,
                name, lines, self.row_ids(params, module_params), record)

    def templates(self, conn) -> dict:
        from engine.templates.store import load_template

        found = {}
        for gear_class in ("spur", "helical"):
            template = load_template(conn, gear_class)   # version and hash, stored with each program
            found[gear_class] = (self.environment.get_template(f"{gear_class}.j2"), template.version, template.hash)
        return found

    def run(self, conn, first: int, last: int) -> list[tuple]:
        from engine.gears.records import load_gears

        planner = Planner(conn)
        templates = self.templates(conn)
        planned = [self.plan(planner, gear, templates) for gear in load_gears(conn, first, last)]
        store(conn, planned)
        return planned


def store(conn, planned: list[tuple]) -> None:
    """Stored the way engine.programs.storage.store_many does: its COPY statements (and binary types, if any)."""
    from psycopg.types.json import Jsonb

    from engine.programs import storage

    with conn.transaction():
        job_ids = [row[0] for row in conn.execute(NEXT_IDS, ("job_id_seq", len(planned)))]
        program_ids = [row[0] for row in conn.execute(NEXT_IDS, ("program_id_seq", len(planned)))]
        with conn.cursor().copy(storage.COPY_JOB) as copy:
            if getattr(storage, "JOB_TYPES", None):
                copy.set_types(storage.JOB_TYPES)
            for job_id, item in zip(job_ids, planned):
                gear_id, gear_class, machine, hob_id, params, module_params = item[:6]
                copy.write_row((job_id, gear_id, gear_class, machine, hob_id, Jsonb(params), Jsonb(module_params),
                                Jsonb(item[11] or {}), params["fixture_id"] or None))
        # Every stored program carries its lineage line (engine.nc.lineage), as store_many adds it.
        lineage = storage.Lineage(conn, [item[2] for item in planned], [(item[1], item[6]) for item in planned],
                                  job_ids)
        with conn.cursor().copy(storage.COPY_PROGRAM) as copy:
            if getattr(storage, "PROGRAM_TYPES", None):
                copy.set_types(storage.PROGRAM_TYPES)
            for program_id, job_id, item in zip(program_ids, job_ids, planned):
                gear_class, machine, (version, template_hash, name, lines, row_ids) = item[1], item[2], item[6:11]
                lines, row_ids = lineage.added(program_id, job_id, machine, gear_class, version, template_hash,
                                               lines, row_ids)
                copy.write_row((program_id, job_id, gear_class, version, template_hash, name, lines, row_ids,
                                None))   # a Jinja2 program has no trace


def run_jinja(conn, pipeline: JinjaPipeline, first: int, last: int) -> tuple[float, int]:
    start = time.perf_counter()
    planned = pipeline.run(conn, first, last)
    conn.commit()
    return time.perf_counter() - start, len(planned)


# --- checks, profile, CLI ------------------------------------------------------------------

def same_programs(conn, pipeline: JinjaPipeline, gear_ids: list[int]) -> tuple[int, int] | None:
    """Our program and the Jinja2 one, line for line and row id for row id, and the same job
    cutting record: the batch's default choices on every sampled gear, each CHOICE_VARIANTS
    entry on a part of them. Returns (programs compared, variant plans refused by our engine
    and so not comparable), or None after printing the first difference."""
    from engine.gears.records import load_gear

    templates = pipeline.templates(conn)
    gears = {gear_id: load_gear(conn, gear_id) for gear_id in gear_ids}
    variant_ids = [gear_id for gear_class in ("spur", "helical")   # half of each class, spread
                   for gear_id in _spread([i for i in gear_ids if gears[i].gear_class == gear_class],
                                          VARIANT_SAMPLE // 2)]
    compared = refused = 0
    for choices, ids in [(Choices(), gear_ids)] + [(variant, variant_ids) for variant in CHOICE_VARIANTS]:
        planner = Planner(conn, choices=choices)
        for gear_id in ids:
            try:
                ours = planner.plan(gears[gear_id])
            except EngineError:   # e.g. a shift step the chosen hob is too short for
                if choices == Choices():
                    raise
                refused += 1
                continue
            theirs = pipeline.plan(planner, gears[gear_id], templates)
            if not _same_program(ours, theirs, gears[gear_id], choices):
                conn.rollback()
                return None
            compared += 1
    conn.rollback()
    return compared, refused


def _spread(ids: list[int], count: int) -> list[int]:
    return ids[::max(1, len(ids) // count)][:count]


def _same_program(ours, theirs: tuple, gear, choices: Choices) -> bool:
    lines, row_ids, cutting = theirs[9], theirs[10], theirs[11]
    if ours.result.lines == lines and ours.result.row_ids == row_ids and ours.cutting == cutting:
        return True
    print(f"MISMATCH gear {gear.id} ({gear.gear_class}, {choices}): the Jinja2 pipeline does not produce our "
          "program; the throughput comparison would be meaningless.")
    ours_lines = ours.result.lines
    for number in range(max(len(ours_lines), len(lines))):
        a = ours_lines[number] if number < len(ours_lines) else "<none>"
        b = lines[number] if number < len(lines) else "<none>"
        if a != b:
            print(f"  line {number + 1}: ours   {a!r}\n  line {number + 1}: jinja2 {b!r}")
            break
    else:
        if ours.result.row_ids != row_ids:
            print(f"  lines equal; row ids differ: ours {ours.result.row_ids} jinja2 {row_ids}")
        else:
            print(f"  programs equal; job.cutting differs: ours {ours.cutting} jinja2 {cutting}")
    return False


def sample_ids(rows: list[tuple]) -> list[int]:
    """SAMPLE gears spread over the batch, both classes, plus one of each kind that is rare."""
    step = max(2, 2 * len(rows) // SAMPLE)   # even indexes are spur gears, odd ones helical
    chosen = {rows[index][0] for start in (0, 1) for index in range(start, len(rows), step)}
    kinds = {(row[1], row[2], row[6]) for row in rows if row[0] in chosen}
    for row in rows:   # and the first gear of every (class, module, hand) combination not yet in
        if (row[1], row[2], row[6]) not in kinds:
            kinds.add((row[1], row[2], row[6]))
            chosen.add(row[0])
    return sorted(chosen)


def profile_ours(conn, first: int, last: int, top: int) -> None:
    import cProfile
    import pstats

    from engine.gears.records import load_gears
    from engine.programs.storage import store_many

    clear_jobs(conn)
    start = time.perf_counter()
    planner = Planner(conn)
    gears = load_gears(conn, first, last)
    loaded = time.perf_counter()
    planned = [planner.plan(gear) for gear in gears]
    computed = time.perf_counter()
    store_many(conn, [item.encoded() for item in planned])
    conn.commit()
    stored = time.perf_counter()
    for gear in gears:   # again, every gear's cutting data now in the Planner's cache
        planner.plan(gear)
    replanned = time.perf_counter()
    count, kinds = len(planned), len(planner._cutting)

    def spent(seconds: float) -> str:
        return f"{seconds * 1000:.0f} ms ({seconds / count * 1e6:.0f} µs/gear)"
    print(f"\nphases of our path (one run, {count} gears, {kinds} distinct cutting-data cache keys): "
          f"load {spent(loaded - start)}, plan {spent(computed - loaded)}, store {spent(stored - computed)}; "
          f"plan again with the cutting data cached {spent(replanned - stored)}, so the case-based cutting "
          f"data cost about {spent(computed - loaded - (replanned - stored))}")

    clear_jobs(conn)
    from engine.programs.instantiate import instantiate_gears

    profiler = cProfile.Profile()
    profiler.enable()
    instantiate_gears(conn, first, last)
    conn.commit()
    profiler.disable()
    for order in ("cumulative", "tottime"):
        print(f"\ncProfile of instantiate_gears ({count} gears), top {top} by {order}:")
        pstats.Stats(profiler, stream=sys.stdout).strip_dirs().sort_stats(order).print_stats(top)


def engine_command() -> str:
    """The console script installed next to this interpreter (the venv's `engine`)."""
    beside = Path(sys.executable).parent / "engine"
    if beside.exists():
        return str(beside)
    found = shutil.which("engine")
    if found is None:
        sys.exit("bench/batch.py: no `engine` console script next to this Python nor on PATH; "
                 "install the project (pip install -e .)")
    return found


def run_cli_once(url: str, first: int, last: int) -> tuple[float, int]:
    command = [engine_command(), "--database-url", url, "instantiate", "--gears", f"{first}-{last}", "--json"]
    start = time.perf_counter()
    completed = subprocess.run(command, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if completed.returncode != 0:
        raise RuntimeError(f"engine CLI exited {completed.returncode}: {completed.stderr.strip()[:500]}")
    return seconds, json.loads(completed.stdout)["programs"]


def check_stored(conn, count: int) -> bool:
    stored = conn.execute("SELECT count(*) FROM program WHERE job_id IN (SELECT id FROM job)").fetchone()[0]
    conn.rollback()
    if stored != count:
        print(f"error: expected {count} stored programs, found {stored}")
    return stored == count


def print_summary(count: int, first: int, last: int, times: dict, cli) -> None:
    rate = {name: count / median(values) for name, values in times.items()}
    best = {name: count / min(values) for name, values in times.items()}
    print()
    labels = {"ours": "ours: instantiate_gears + commit",
              "ours-2-workers": "ours with --workers 2",
              "jinja2": "jinja2: same plan, render, limit check, COPY",
              "jinja2-nocheck": "jinja2 without the limit check (information)"}
    for name, label in labels.items():
        print(f"{label:45s}: median {rate[name]:6.0f} programs/s (best {best[name]:.0f}; "
              f"{', '.join(f'{s:.2f}' for s in times[name])} s)")
    if cli is not None:
        seconds, programs = cli
        print(f"engine instantiate --gears {first}-{last} --json (CLI, once, with process start): "
              f"{seconds:.2f} s = {programs / seconds:.0f} programs/s")
    ratio = rate["ours"] / rate["jinja2"]
    print(f"ratio ours/jinja2 = {ratio:.2f} (target >= {TARGET_RATIO:g}): {verdict(ratio >= TARGET_RATIO)}")
    print(f"ratio ours/jinja2-nocheck = {rate['ours'] / rate['jinja2-nocheck']:.2f} (information)")
    print(f"ours {rate['ours']:.0f} programs/s (target >= {TARGET_RATE}): {verdict(rate['ours'] >= TARGET_RATE)}")
    scaling = rate["ours-2-workers"] / rate["ours"]
    print(f"ratio --workers 2 / one worker = {scaling:.2f} (target >= {TARGET_WORKERS_RATIO:g}): "
          f"{verdict(scaling >= TARGET_WORKERS_RATIO)}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--reps", type=int, default=3, help="alternated repetitions of each pipeline (default 3)")
    parser.add_argument("--count", type=int, default=10_000, help="gears in the batch (default 10000)")
    parser.add_argument("--no-cli", action="store_true", help="skip the one run through the `engine` CLI")
    parser.add_argument("--profile", action="store_true",
                        help="also time the phases of our path and print cProfile hotspots")
    parser.add_argument("--profile-count", type=int, default=PROFILE_GEARS,
                        help=f"gears (the batch's first) that --profile times and profiles (default {PROFILE_GEARS})")
    parser.add_argument("--top", type=int, default=25, help="rows of each cProfile listing (default 25)")
    args = parse_arguments(parser, argv, smoke={"count": 20, "reps": 1})

    import psycopg

    first, last = FIRST_ID, FIRST_ID + args.count - 1
    pipeline = JinjaPipeline(jinja_environment())
    unchecked = JinjaPipeline(pipeline.environment, check=False)
    with bench_database(args.database_url, "bench_batch") as url, psycopg.connect(url) as conn:
        rows = generate_gears(first, args.count)
        insert_gears(conn, rows)
        spur = sum(row[1] == "spur" for row in rows)
        print(f"batch: {args.count} gears ({spur} spur, {args.count - spur} helical) ids {first}..{last}, "
              f"{args.reps} alternated repetitions, interpreter {sys.executable}")

        sample = sample_ids(rows)
        checked = same_programs(conn, pipeline, sample)
        if checked is None:
            return 1
        compared, refused = checked
        print(f"check: the Jinja2 pipeline renders our programs exactly (lines, row ids, job.cutting): "
              f"{len(sample)} sampled gears with the batch's choices, {compared - len(sample)} more plans under "
              f"{len(CHOICE_VARIANTS)} other choice sets ({refused} refused by the shared model)")

        runs = {"ours": run_ours, "ours-2-workers": lambda c, a, b: run_ours(c, a, b, workers=2),
                "jinja2": lambda c, a, b: run_jinja(c, pipeline, a, b),
                "jinja2-nocheck": lambda c, a, b: run_jinja(c, unchecked, a, b)}
        for run in runs.values():   # warm-up, untimed: imports, compiled templates, table files
            clear_jobs(conn)
            run(conn, first, min(last, first + WARMUP_GEARS - 1))

        times = {name: [] for name in runs}
        for repetition in range(args.reps):
            order = list(runs) if repetition % 2 == 0 else list(reversed(runs))
            for name in order:
                clear_jobs(conn)
                seconds, count = runs[name](conn, first, last)
                assert count == args.count, (name, count)
                times[name].append(seconds)
        if not check_stored(conn, args.count):
            return 1

        cli = None
        if not args.no_cli:
            clear_jobs(conn)
            cli = run_cli_once(url, first, last)

        if args.profile:
            profile_ours(conn, first, min(last, first + args.profile_count - 1), args.top)

    print_summary(args.count, first, last, times, cli)
    return 0


if __name__ == "__main__":
    sys.exit(main())
