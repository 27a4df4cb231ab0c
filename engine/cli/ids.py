"""The types of id options and arguments: the range of the column each names (schema/schema.sql),
so an id beyond it (`--gear 99999999999`) is bad input said in one line, exit 1, like any other
bad option, and never reaches the database as a number its column cannot hold."""
from __future__ import annotations

import click

INTEGER_MAX = 2**31 - 1   # PostgreSQL integer
BIGINT_MAX = 2**63 - 1    # PostgreSQL bigint (bigserial)

GEAR_ID = click.IntRange(1, INTEGER_MAX)        # gear.id integer CHECK (id > 0)
JOB_ID = click.IntRange(1, BIGINT_MAX)          # job.id bigserial
PROGRAM_ID = click.IntRange(1, BIGINT_MAX)      # program.id bigserial
ROW_ID = click.IntRange(0, INTEGER_MAX)         # assembly.id integer CHECK (id >= 0)
VERSION = click.IntRange(0, INTEGER_MAX)        # gear_class.template_version integer CHECK (>= 0)
