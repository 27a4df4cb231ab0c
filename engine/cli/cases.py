"""Commands for cutting data from the machining history: `engine suggest`, `engine cases`."""
from __future__ import annotations

import click

from .context import connection, emit_json
from .ids import GEAR_ID, JOB_ID
from .output import Column, emit_list, list_options

CASE_TABLE_COLUMNS = {   # column -> heading, for the small tables printed
    "id": "case", "distance": "distance", "module": "m", "teeth": "z", "material": "material", "hardness": "HB",
    "quality_grade": "grade", "hob_material": "hob", "hob_coating": "coating", "hob_starts": "z0",
    "hob_tip_diameter": "da0", "cut": "cut", "hob_speed": "n0", "axial_feed": "axial", "radial_feed": "radial",
    "source": "source",
}
CASE_LIST_COLUMNS = tuple(Column(heading, "case_id" if key == "id" else key)
                          for key, heading in CASE_TABLE_COLUMNS.items() if key != "distance")


@click.command()
@click.option("--gear", "gear_id", type=GEAR_ID, required=True, help="Gear id to propose cutting data for.")
@click.option("--top", type=click.IntRange(min=1), default=3, show_default=True,
              help="Nearest cases per cut kind (rough, finish).")
@click.option("--machine", help="Machine record (default hobber-840d): caps the hob speed.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of prose.")
@click.pass_context
def suggest(ctx, gear_id, top, machine, as_json):
    """Propose hob speed and feeds for a gear from the nearest cases of the machining history.

    Prints the hob the library chooses, the nearest cases per cut kind with their distance,
    the proposal (n0, v, feeds in mm/min and mm per workpiece revolution) and plausibility notes.
    """
    from ..gears.cases import suggest_for_gear
    from ..programs import all_models  # noqa: F401  (registers every model)

    with connection(ctx) as conn:
        suggestion = suggest_for_gear(conn, gear_id, machine, top=top)
    emit_json(_suggestion_json(suggestion)) if as_json else click.echo(_suggestion_text(suggestion))


def _suggestion_json(s) -> dict:
    return {"gear_id": s.gear.id, "hob": {"hob_id": s.hob.id, "reason": s.hob_reason}, "machine": s.machine.name,
            "hob_speed": s.cutting.hob_speed, "cutting_speed": round(s.cutting.cutting_speed, 1),
            "source": s.cutting.source, "notes": s.notes, "cases": _records(s.cases),
            **{cut: {**s.feeds(cut), "source": p.source, "case_ids": list(p.case_ids)}
               for cut, p in s.proposals.items()}}


def _suggestion_text(s) -> str:
    gear, cutting = s.gear, s.cutting
    lines = [f"gear {gear.id}: m{gear.module:g} z{gear.teeth} {gear.material or '?'} "
             f"{'' if gear.hardness is None else f'{gear.hardness:g} HB '}grade {gear.quality_grade or '?'}",
             f"hob {s.hob_reason}",   # the reason starts with the hob id
             f"machine {s.machine.name} (hob spindle max {s.machine.spindle_max:g} r/min)"]
    for cut in s.proposals:
        cases = s.cases[s.cases.cut == cut]
        lines += ["", f"{cut} cases (nearest {len(cases)}):" if len(cases) else f"{cut}: no cases in the history"]
        if len(cases):
            lines.append(_table(cases.drop(columns="cut")))
    lines += ["", f"proposal: n0 {cutting.hob_speed} r/min, v {cutting.cutting_speed:.1f} m/min  ({cutting.source})"]
    for cut in s.proposals:
        f = s.feeds(cut)
        lines.append(f"  {cut:6}  axial {f['axial_feed']:.1f} mm/min ({f['axial_feed_per_rev']:.2f} mm/rev)  "
                     f"radial {f['radial_feed']:.1f} mm/min ({f['radial_feed_per_rev']:.2f} mm/rev)")
    lines += ["", "notes:", *(f"  - {note}" for note in s.notes)] if s.notes else ["", "notes: none"]
    return "\n".join(lines)


def _table(frame) -> str:
    shown = frame[[c for c in CASE_TABLE_COLUMNS if c in frame.columns]].rename(columns=CASE_TABLE_COLUMNS)
    return shown.to_string(index=False, na_rep="-", float_format=lambda v: f"{v:g}")


def _records(frame) -> list[dict]:
    plain = frame.astype(object).where(frame.notna(), None)
    return plain.to_dict("records")


@click.group()
def cases():
    """The machining history (cutting cases) that `engine suggest` reasons over."""


@cases.command("list")
@list_options("cases")
@click.pass_context
def cases_list(ctx, output):
    """List every cutting case: gear and hob features, cut, n0 r/min, feeds mm/min, source. --csv writes
    the file `engine cases import` reads (id first, every value as stored), which `engine cases import
    FILE --replace` takes back unchanged.

    Example: engine cases list --csv > cases.csv
    """
    with connection(ctx) as conn:
        if output == "csv":
            from ..gears.case_import import FILE_COLUMNS, export_cases

            return emit_list(output, "cases", tuple(Column(name, name) for name in FILE_COLUMNS), export_cases(conn))
        from ..gears.cases import case_records

        history = case_records(conn)
    emit_list(output, "cases", CASE_LIST_COLUMNS, history)


@cases.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Replace the stored cases whose id the file gives, printing each changed field (old → new).")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: {added: N, replaced: N, changes: [{case_id, field, old, new}]}.")
@click.pass_context
def cases_import(ctx, csv_file, replace, as_json):
    """Add the cases of CSV_FILE to the machining history (the columns of `engine cases list --csv`, those
    of seed_templates/cases.csv with an id first). A row without an id is a new case; an id already
    stored is refused unless --replace. A case confirmed from a job is changed in no field: it records
    what that job ran. Any bad row stops the whole file (nothing stored).

    Example: engine cases import cases.csv --replace
    """
    from ..db.replacing import plain
    from ..gears.case_import import import_cases

    with connection(ctx) as conn:
        added, replaced, changes = import_cases(conn, csv_file, replace=replace)
    if as_json:
        return emit_json({"added": added, "replaced": replaced, "changes": [
            {"case_id": c.key, "field": c.field, "old": plain(c.old), "new": plain(c.new)} for c in changes]})
    for change in changes:
        click.echo(change.said("case"))
    click.echo(f"{csv_file}: added {added} case(s), replaced {replaced}")


@cases.command("confirm")
@click.option("--job", "job_id", type=JOB_ID, required=True, help="Job whose stored cutting data proved good.")
@click.pass_context
def cases_confirm(ctx, job_id):
    """Confirm a job: its stored cutting data become new cases (one per cut kind).

    The job's last program vouches for the data: it must be the rendering of the template
    version and job it names; a program that is not (MISMATCH), or cannot be rendered again
    because the job was edited since (UNCHECKED), or whose rendering the verifier or the
    simulation refuses now (REFUSED), is refused and nothing is added. Every value a case takes
    from job.cutting (the hob speed, each cut kind's axial and radial feed) must be what that
    program ran (its trace): a difference is refused and nothing is added.
    """
    from ..gears.cases import confirm_job
    from ..programs.case_evidence import check_case_evidence
    from ..programs.rendering import checked_last_program

    with connection(ctx) as conn, conn.transaction():
        checked = checked_last_program(conn, job_id, "the cutting history; nothing confirmed")
        if checked is not None:   # the database refuses a job without a program itself
            check_case_evidence(conn, job_id, checked.program_id)
        ids = confirm_job(conn, job_id)
    click.echo(f"job {job_id} confirmed: added case(s) {', '.join(f'#{i}' for i in ids)}")
