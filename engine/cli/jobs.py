"""`engine jobs list|show|delete`: the jobs stored (a gear on a machine with its parameters) and
the programs made from each."""
from __future__ import annotations

import json

import click

from ..db.origin import LAST_PLANT
from .context import connection
from .ids import GEAR_ID, JOB_ID
from .output import Column, day, day_options, emit_list, emit_record, list_options

JOB_COLUMNS = (
    Column("job", "job_id"), Column("plant", "plant"), Column("gear", "gear_id"), Column("class", "class"),
    Column("machine", "machine"),
    Column("hob", "hob_id"), Column("programs", "program_count"), Column("made", "created_at"),
    Column("confirmed", "confirmed_at"),
)
JOB_FIELDS = JOB_COLUMNS[:6] + (
    Column("made", "created_at"), Column("confirmed", "confirmed_at"), Column("drawing", "drawing"),
    Column("parameters", "params", lambda params: json.dumps(params, sort_keys=True)),
    Column("module parameters", "module_params", lambda params: json.dumps(params, sort_keys=True)),
    Column("cutting data", "cutting", lambda cutting: json.dumps(cutting, sort_keys=True)),
)
PROGRAM_COLUMNS = (Column("program", "program_id"), Column("name", "name"), Column("version", "template_version"),
                   Column("draft", "draft"), Column("verifier", "verifier"), Column("rendering", "rendering"),
                   Column("stored", "created_at"))


@click.group("jobs")
def jobs():
    """Jobs: a gear on a machine with every parameter its template needs; list, show, delete."""


@jobs.command("list")
@click.option("--class", "gear_class", help="Only jobs of this class.")
@click.option("--gear", "gear_id", type=GEAR_ID, help="Only jobs of this gear (a gear of --plant's, else of this "
              "database: gear ids of plants collide).")
@click.option("--plant", type=click.IntRange(0, LAST_PLANT), help="Only jobs made at this plant (0: the head office).")
@day_options("jobs made")
@list_options("jobs")
@click.pass_context
def jobs_list(ctx, gear_class, gear_id, plant, since, until, output):
    """The jobs stored, one line each: the plant that made it (0: the head office; a head office
    holds its plants' jobs as history), gear, class, machine, hob, programs made, when.

    Example: engine jobs list --gear 42 --json
    """
    from ..programs.job_records import list_jobs

    with connection(ctx) as conn:
        found = list_jobs(conn, gear_class, gear_id, day(since), day(until), plant)
    emit_list(output, "jobs", JOB_COLUMNS, found)


@jobs.command("show")
@click.argument("job_id", type=JOB_ID)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {\"job\": {..., params, programs}}.")
@click.pass_context
def jobs_show(ctx, job_id, as_json):
    """One job as stored: gear, class, machine, hob, its parameters and cutting data, its programs.

    Example: engine jobs show 7
    """
    from ..programs.job_records import job_details

    with connection(ctx) as conn:
        job = job_details(conn, job_id)
    emit_record(as_json, "job", JOB_FIELDS, job, (("programs", PROGRAM_COLUMNS, "programs"),))


@jobs.command("delete")
@click.argument("job_id", type=JOB_ID)
@click.option("--yes", is_flag=True, help="Delete it (without: say what would be deleted, exit 1).")
@click.pass_context
def jobs_delete(ctx, job_id, yes):
    """Delete a job no program and no cutting case refers to (a job with programs is kept:
    programs are records nobody rewrites).

    Example: engine jobs delete 7 --yes
    """
    from ..programs.job_records import delete_job

    with connection(ctx) as conn:
        deleted = delete_job(conn, job_id, yes)
    click.echo(f"deleted {deleted}")
