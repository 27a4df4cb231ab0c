"""Which version of a class's template runs (design notes §10, issue 15): runners and
`engine instantiate` get the class's latest released version; an editor trying a change gets
the draft (`--draft`), the class's current rows, and its programs are recorded as drafts.

Every committed change of a template is a stored version (template_version_rows); the class's
current version is its draft until `engine template release` records it in template_release."""
from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from types import MappingProxyType
from typing import TYPE_CHECKING

from msgspec.structs import replace

from ..db.connection import scalar
from ..errors import EngineError
from .rows import Template, TemplateRow
from .translations import load_translations

if TYPE_CHECKING:
    from ..db.connection import Connection

RELEASED = """
SELECT v.version, v.rows FROM template_release r
JOIN template_version_rows v ON v.gear_class = r.gear_class AND v.version = r.version
WHERE r.gear_class = %s ORDER BY r.id DESC LIMIT 1"""
RELEASED_VERSION = "SELECT released_version(%s)"
VERSION_ROWS = "SELECT rows FROM template_version_rows WHERE gear_class = %s AND version = %s"

# Classes whose template is a given stored version while a release is re-checked (pinned_templates).
_PINNED: ContextVar[Mapping[str, Template]] = ContextVar("pinned_templates", default=MappingProxyType({}))


def released_template(conn: Connection, gear_class: str) -> Template:
    """The class's latest released template: what the shop floor runs."""
    found = conn.execute(RELEASED, (gear_class,)).fetchone()
    if found is None:
        from .store import load_template  # the store: only where no release is found (issue 28: start-up)

        load_template(conn, gear_class)   # an unknown or empty class is refused as such
        raise EngineError(f"class {gear_class!r} has no released template version; an editor tries the draft with "
                          f"--draft, and `engine template release --class {gear_class}` releases it")
    rows = tuple(TemplateRow(**row) for row in found[1])
    if not rows:
        raise EngineError(f"class {gear_class!r} version {found[0]} (released) has no template rows")
    return Template(gear_class, found[0], rows, load_translations(conn, rows))


def draft_template(conn: Connection, gear_class: str) -> Template:
    """The class's current rows (its draft, or its released version if it has no draft), marked
    whether they are a draft."""
    from .store import load_template  # the store: only for a draft, never on a runner's path (issue 28)

    template = load_template(conn, gear_class)
    released = scalar(conn.execute(RELEASED_VERSION, (gear_class,)))
    return replace(template, draft=released != template.version)


def runnable_template(conn: Connection, gear_class: str, draft: bool = False) -> Template:
    """The template a job of the class is made with: the draft if asked for, else the released one
    (or, while a release is re-checked, the stored version pinned for the class)."""
    pinned = _PINNED.get().get(gear_class)
    if pinned is not None:
        return pinned
    return draft_template(conn, gear_class) if draft else released_template(conn, gear_class)


def stored_template(conn: Connection, gear_class: str, version: int) -> Template:
    """The class's assembled rows as stored for `version` (template_version_rows)."""
    found = conn.execute(VERSION_ROWS, (gear_class, version)).fetchone()
    if found is None:
        raise EngineError(f"class {gear_class!r} version {version} is not stored; see `engine template history "
                          f"--class {gear_class}`")
    rows = tuple(TemplateRow(**row) for row in found[0])
    return Template(gear_class, version, rows, load_translations(conn, rows))


@contextmanager
def pinned_templates(templates: dict[str, Template]) -> Iterator[None]:
    """Within the block, runnable_template gives these stored versions for their classes: the
    golden tests of a release re-run against the rows it released, whatever is released now."""
    token = _PINNED.set(MappingProxyType({**_PINNED.get(), **templates}))
    try:
        yield
    finally:
        _PINNED.reset(token)


def released_version(conn: Connection, gear_class: str) -> int | None:
    return scalar(conn.execute(RELEASED_VERSION, (gear_class,)))
