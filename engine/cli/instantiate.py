"""`engine instantiate`: the program of a gear, a stored job, a class's job, or a batch of gears."""
from __future__ import annotations

import re
from functools import partial
from typing import TYPE_CHECKING

import click
from msgspec.structs import replace

from ..errors import EngineError
from .context import connection, emit_json, settings
from .ids import GEAR_ID, JOB_ID

if TYPE_CHECKING:
    from ..db.connection import Connection

RANGE = re.compile(r"^\s*(\d+)\s*(?:-\s*(\d+))?\s*$")


def parse_range(text: str, option: str = "--gears") -> tuple[int, int]:
    match = RANGE.match(text)
    if not match:
        raise EngineError(f"{option} {text!r} is not a range like 1-5000 or 42")
    first = int(match.group(1))
    last = int(match.group(2) or first)
    if last < first:
        raise EngineError(f"{option} {text!r}: the range ends before it starts")
    return first, last


@click.command()
@click.option("--gear", "gear_id", type=GEAR_ID, help="Gear id: compute a new job and its program.")
@click.option("--job", "job_id", type=JOB_ID, help="Stored job id: instantiate again with its (edited) parameters, "
              "checked as a new job's: its hob must be one `engine hobs match` accepts, its gear, hob and machine "
              "values those of the records, its speeds and feeds within a new job's bounds.")
@click.option("--gears", "gear_range", help="Batch: gear ids FIRST-LAST (all stored, or none unless --skip-bad).")
@click.option("--class", "gear_class", help="A class without a model (made by engine import-nc): a new job of it "
              "with --params, on --machine, its program read by the machine's verifier.")
@click.option("--params", "params_file", type=click.Path(dir_okay=False), help="With --class: parameter values, JSON "
              "{name: value} (or {name: {\"value\": …, \"addresses\": […]}}) or CSV name,value, as import-nc's; "
              "names not given keep the values the class was imported with, unknown names are refused.")
@click.option("--unverified", is_flag=True, help="With --class: store the program without the verifier's reading "
              "(a dialect it does not know, a program it refuses), marked UNVERIFIED in its record and lineage line. "
              "Never written to a file (not with --out, nor a config output folder): a program that reaches the "
              "machine is one the verifier read.")
@click.option("--jobs", "job_range", help="Batch: stored job ids FIRST-LAST made again with their stored parameters.")
@click.option("--all", "all_gears", is_flag=True, help="Batch: every gear.")
@click.option("--out", type=click.Path(), help="Write the .MPF file here after the programs are committed: a "
              "batch always into this folder, one program into it if it is a folder or ends with /. The folder "
              "must exist (else nothing is stored) unless --mkdir.")
@click.option("--force", is_flag=True,
              help="Replace files that exist in --out, each in one step (else nothing is stored).")
@click.option("--mkdir", is_flag=True, help="Create the folder of --out (or of the config file's machine folder) "
              "and the folders above it if missing; without it a missing folder is refused (a typo in a path).")
@click.option("--machine", help="Machine record (default: the config file's machine, else hobber-840d for a "
              "gear; with --class one must be named).")
@click.option("--cuts", type=click.IntRange(1, 2), help="1 = single cut, 2 = rough then finish (default by module).")
@click.option("--coolant/--no-coolant", default=True, show_default=True, help="Coolant M8/M9.")
@click.option("--shift-y", type=float, default=0.0, help="Hob shift position Y for this part, mm.")
@click.option("--shift-per-part", type=float, default=0.0,
              help="Shift the hob by this many mm every part (R11 on an 840D, #500 on a Fanuc counts), wrapping "
                   "within the hob's usable length.")
@click.option("--feed-mode", metavar="MODE",
              help="Axial pass direction: climb, conventional or conventional-climb (rough conventional, finish "
                   "climb); a cluster gear's units each their own, unit 1's/unit 2's (climb/conventional). "
                   "Default: the engine's choice, climb first, another direction where climb does not fit (the "
                   "note says why).")
@click.option("--tailstock/--no-tailstock", default=True, show_default=True, help="Tailstock clamp M20/M21.")
@click.option("--fixture", "fixture", help="Work-holding id of the library (`engine fixtures list`) to clamp the gear "
              "on; refused if it does not fit and clear the gear (default: the machine's own fixture and tailstock "
              "when they clear the root, else the largest work-holding that does, as `engine fixtures match`).")
@click.option("--worm-feed", type=click.Choice(["radial", "tangential"]), default="radial", show_default=True,
              help="Worm wheels: radial plunge, or tangential feed along Y.")
@click.option("--allowance", type=float, default=0.0, show_default=True,
              help="Radial process allowance left at the final cut for shaving or grinding, mm (the final centre "
                   "distance is raised by it; the paper's 2.5).")
@click.option("--hob-speed", type=click.IntRange(min=1), help="Override the hob speed n0, r/min (above 0).")
@click.option("--workers", type=click.IntRange(1, 64), default=1, show_default=True,
              help="Batch: plan the gears in this many processes (all stored in one transaction, or none).")
@click.option("--explain", is_flag=True,
              help="Also say why each row emitted its line or not, with the values (on stderr; in --json: explain).")
@click.option("--draft", is_flag=True, help="Use the class's draft (an editor trying a change), not its released "
              "template; the program is recorded as a draft. Never written to a file: refused with --out or a "
              "config output folder (print it, or try it with --dry-run).")
@click.option("--dry-run", is_flag=True, help="Compute and check as a stored run does, store nothing: print the "
              "program (its lineage line says PROGRAM DRY-RUN), or a batch's count of what it would store. "
              "Not with --out.")
@click.option("--skip-bad", is_flag=True, help="Batch: store the good programs and list the bad gears or jobs "
              "skipped (else any bad one stores nothing).")
@click.option("--quiet", is_flag=True, help="Batch: print only the summary line (programs stored, skipped, "
              "notes counted by kind); else the first 3 notes of each kind are shown, all with --json.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object (program_id, path, lines, ...).")
@click.pass_context
def instantiate(ctx, gear_id, job_id, gear_class, params_file, unverified, gear_range, job_range, all_gears, out,
                force, mkdir, machine, cuts, coolant, shift_y, shift_per_part, feed_mode, tailstock, fixture, worm_feed,
                allowance, hob_speed, workers, explain, draft, dry_run, skip_bad, quiet, as_json):
    """Produce the NC program of a gear (or a stored job, a job of an imported class, or a batch of gears).

    The program is checked against the machine's limits and proved by the
    simulation, stored with the template version it came from, printed (single
    program) and written to --out. --dry-run makes the same checks and stores
    nothing (no job, no program, no file).

    A batch (--gears, --all, --jobs) tries every gear or job and names each bad
    one with its reason, with a progress bar on a terminal. Exit code 0: stored
    (with --skip-bad: the good ones, the bad ones listed on stderr); 1: bad
    input, or any bad gear or job without --skip-bad, or none good: nothing
    stored; 2: a bug; 3: stored, but the files not written (the error names the
    programs and the files; the files there are as they were, or it says which
    were replaced); 130: interrupted with Ctrl-C (workers too), nothing stored.

    --class C --params P.json makes a job of a class without a model (engine
    import-nc) on a lathe: its program is read by the machine's verifier, and
    with its imported values it is the imported program again. The turning
    simulation proves it without a drawing record, against the blank given in
    --params (stock_diameter, stock_z_front, stock_z_back, mm, all three or
    none) or else the one its program implies (assumed: stored for review,
    never written to a file); proved against a stated blank, it is written like
    any program, and its notes say what was not checked.

    Example: engine instantiate --gear 42 --out /srv/nc/
    """
    from ..hobbing.choices import Choices
    from ..programs.config import line_ending
    from ..programs.instantiate import instantiate_gear
    from ..programs.options import RunMode
    from ..programs.outputs import line_endings

    _refuse_all_but_one_job(gear_id, job_id, gear_class, gear_range, job_range, all_gears)
    _refuse_options_of_other_jobs(ctx, gear_class is not None)
    batch = bool(gear_range or job_range or all_gears)
    workers = where_it_applies(ctx, "workers", workers, workers == 1 or bool(gear_range or all_gears),
                               "--workers plans a batch of gears: use it with --gears FIRST-LAST or --all")
    explain = where_it_applies(ctx, "explain", explain, not (explain and batch),
                               "--explain explains one program: use it with --gear or --job, and "
                               "`engine explain --program ID` for the programs of a batch")
    _refuse_new_job_choices_for_stored_jobs(ctx, job_id is not None or bool(job_range))
    choices = Choices(cuts=cuts, coolant=coolant, shift_y=shift_y, shift_per_part=shift_per_part,
                      feed_mode=feed_mode, tailstock=tailstock, worm_feed=worm_feed,
                      allowance=allowance, fixture=fixture)
    overrides = {"hob_speed": hob_speed}
    config = settings(ctx)   # the config file: the machine's output folder and line endings (over the class's)
    output = _output(config, machine, out, force, new_job_written=not (dry_run or job_id is not None or job_range))
    output = replace(output, mkdir=where_it_applies(ctx, "mkdir", mkdir, not mkdir or output.out is not None,
                                                    "--mkdir creates the folder of --out: give --out too"))
    skip_bad = where_it_applies(ctx, "skip_bad", skip_bad, not skip_bad or batch,
                                "--skip-bad skips the bad gears of a batch: use it with --gears, --jobs or --all")
    quiet = where_it_applies(ctx, "quiet", quiet, not quiet or batch,
                             "--quiet shortens a batch's report: use it with --gears, --jobs or --all")
    mode = RunMode(draft=draft, dry_run=dry_run, skip_bad=skip_bad, workers=workers)
    with connection(ctx) as conn, line_endings(partial(line_ending, config)):
        if gear_id is not None:
            program = instantiate_gear(conn, gear_id, machine=machine, choices=choices, overrides=overrides,
                                       output=output, mode=mode)
        elif job_id is not None:
            from ..programs.remake import instantiate_job  # a stored job's path only (issue 28: start-up)
            program = instantiate_job(conn, job_id, output=output, mode=mode)
        elif gear_class is not None:
            job = _class_job(conn, gear_class, params_file, machine, output, mode, unverified)
            return _report_class_job(job, as_json, explain)
        else:
            from .batch_report import report_batch  # batches only: one gear's start-up does not load it
            return report_batch(_batch(conn, job_range, gear_range, machine, choices, overrides, output, mode),
                                output.out, as_json, quiet)
    _report_program(program, as_json, explain)


def _refuse_all_but_one_job(gear_id, job_id, gear_class, gear_range, job_range, all_gears) -> None:
    """One invocation makes one kind of job: a gear's, a stored one's, a class's, or a batch."""
    chosen = [name for name, value in (("--gear", gear_id), ("--job", job_id), ("--class", gear_class),
                                       ("--gears", gear_range), ("--jobs", job_range), ("--all", all_gears))
              if value not in (None, False)]
    if len(chosen) != 1:
        raise EngineError("give exactly one of --gear ID, --job ID, --class C, --gears FIRST-LAST, --jobs FIRST-LAST, "
                          "--all")


def _output(config, machine: str | None, out, force: bool, new_job_written: bool):
    """Where the files go: --out, else (a new job, not a dry run) the machine's output folder of
    the config file, else nowhere. --force with nowhere to write would replace nothing: refused."""
    from ..programs.config import output_folder
    from ..programs.options import Output

    out = output_folder(config, machine, out) if new_job_written else out   # a dry run writes no file
    if force and not out:
        raise EngineError("--force replaces files in --out: give --out too")
    return Output(out=out, force=force)


def _batch(conn: Connection, job_range, gear_range, machine, choices, overrides, output, mode):
    """A batch of stored jobs made again (--jobs), or of gears (--gears, --all), with a progress
    bar on a terminal."""
    from ..programs.instantiate import instantiate_gears
    from ..programs.remake import instantiate_jobs
    from .progress import progress_bar  # a batch's bar only (issue 28: start-up)

    with progress_bar("instantiate") as progress:
        mode = replace(mode, progress=progress)
        if job_range:
            return instantiate_jobs(conn, *parse_range(job_range, "--jobs"), output=output, mode=mode)
        first, last = parse_range(gear_range) if gear_range else (None, None)
        return instantiate_gears(conn, first, last, machine=machine, choices=choices, overrides=overrides,
                                 output=output, mode=mode)


def where_it_applies(ctx, name: str, value, applies: bool, refusal: str):
    """The option's value where it applies to the invocation. Typed on the command line where it
    does not, it is refused (it would silently do nothing); a default of the environment or the
    config file (a shop's batch habit, e.g. ENGINE_INSTANTIATE_WORKERS=4) is for the invocations
    it applies to, and is ignored by the others: the option's built-in default."""
    if applies:
        return value
    if ctx.get_parameter_source(name) is click.core.ParameterSource.COMMANDLINE:
        raise EngineError(refusal)
    return next(parameter.default for parameter in ctx.command.params if parameter.name == name)


NEW_JOB_CHOICES = ("machine", "cuts", "coolant", "shift_y", "shift_per_part", "feed_mode", "tailstock",
                   "worm_feed", "allowance", "hob_speed", "fixture")


HOBBING_CHOICES = NEW_JOB_CHOICES[1:]   # all but --machine: what a hobbing model computes a job with
CLASS_JOB_OPTIONS = ("params_file", "unverified")


def _given(ctx, names) -> list[click.Parameter]:
    """The options of `names` typed on the command line."""
    return [parameter for parameter in ctx.command.params if parameter.name in names
            and ctx.get_parameter_source(parameter.name) is click.core.ParameterSource.COMMANDLINE]


def _spelled(parameter: click.Parameter) -> str:
    return "/".join(parameter.opts + parameter.secondary_opts)


def _refuse_options_of_other_jobs(ctx, class_job: bool) -> None:
    """A class's job has no hob, cuts or feeds to choose; --params and --unverified are its alone:
    given elsewhere, either would silently do nothing."""
    given = _given(ctx, HOBBING_CHOICES) if class_job else _given(ctx, CLASS_JOB_OPTIONS)
    if given and class_job:
        raise EngineError(f"{_spelled(given[0])} is a choice of a hobbing job (--gear, --gears, --all); a job of "
                          "--class takes its values from --params")
    if given:
        raise EngineError(f"{_spelled(given[0])} applies to a job of a class with --class C only")


def _refuse_new_job_choices_for_stored_jobs(ctx, stored_jobs: bool) -> None:
    """A stored job is made with its stored parameters: a choice given with --job/--jobs would
    silently do nothing."""
    given = _given(ctx, NEW_JOB_CHOICES)
    if stored_jobs and given:
        option = _spelled(given[0])
        raise EngineError(f"{option} applies to a new job (--gear, --gears, --all); a stored job is made with its "
                          "stored parameters: edit job.params in SQL to change them")


def _class_job(conn: Connection, gear_class, params_file, machine, output, mode, unverified):
    """The job of the class with the values of --params (the class's imported ones without it)."""
    from ..library.nc_import import read_params
    from ..programs.class_jobs import instantiate_class

    given = read_params(params_file) if params_file else {}
    return instantiate_class(conn, gear_class, given, machine=machine, source=params_file or "parameters",
                             output=output, mode=mode, unverified=unverified)


def _report_class_job(job, as_json: bool, explain: bool) -> None:
    if job.taken and not as_json:
        click.echo(f"imported values kept (not in --params): {', '.join(job.taken)}", err=True)
    _report_program(job.program, as_json, explain, {"machine": job.machine, "given": list(job.given),
                                                    "taken": list(job.taken)})


def _report_program(program, as_json: bool, explain: bool, more: dict | None = None) -> None:
    rows = _explained(program) if explain else []
    dry_run = program.program_id is None
    if as_json:
        emit_json({"program_id": program.program_id, "job_id": program.job_id, "name": program.name,
                   "path": program.path, "lines": len(program.lines), "class": program.gear_class,
                   "template_version": program.template_version, "template_hash": program.template_hash,
                   "notes": list(program.notes), "unverified": program.unverified, **(more or {}),
                   **({"explain": [row.as_dict() for row in rows]} if explain else {}),
                   **({"dry_run": True, "text": program.text} if dry_run else {})})
        return
    for row in rows:
        click.echo(row.sentence(), err=True)
    for note in program.notes:
        click.echo(f"note: {note}", err=True)
    if program.path is None:
        click.echo(program.text, nl=False)
    click.echo(_program_summary(program) + (f" written to {program.path}" if program.path else ""), err=True)


def _explained(program) -> list:
    from ..programs.explain import explained_rows  # with --explain only (issue 28: start-up)

    return explained_rows(program.trace, program.lines, program.row_ids)


def _program_summary(program) -> str:
    if program.program_id is None:
        job = f"job {program.job_id}, " if program.job_id is not None else ""
        checked = "UNVERIFIED (not read by a verifier)" if program.unverified else "checked"
        return (f"dry run: program {program.name} ({job}{len(program.lines)} lines) from {program.gear_class} "
                f"v{program.template_version} {checked}; nothing stored")
    return (f"program {program.program_id} (job {program.job_id}, {len(program.lines)} lines) "
            f"from {program.gear_class} v{program.template_version}" + (" UNVERIFIED" if program.unverified else ""))
