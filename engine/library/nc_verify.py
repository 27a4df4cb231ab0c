"""The proof of an import (engine.library.nc_import), computed while the rows are written: the
rows checked as every writer's rows are (engine.templates.checks), then instantiated with the
job's parameters and compared with the file line for line. The import waits for it before it
commits, so nothing is stored that is not proved; the database spends its seconds on the rows
(components, audit, version) while this thread spends its own on Python (psycopg waits for the
server without the interpreter lock).

The rows it instantiates are the rows the class stores: the import compares them with the
stored template before it commits. They cannot read the template's version (an imported row
reads only the job's parameters), so the one they are run with is the stored one or any."""
from __future__ import annotations

import threading

from ..errors import EngineError
from ..templates.checks import check_rows
from ..templates.decision_table import CompiledTemplate, rows_compiled_once
from ..templates.rows import Template


class Proof(threading.Thread):
    """`start_on(gear_class, rows)` (the check replace_template calls) starts it; `verdict()`
    waits for it and raises what it found."""

    def __init__(self, params: dict, lines: list[str], path):
        super().__init__(name="import-nc proof", daemon=True)
        self.params, self.lines, self.path = params, lines, path
        self.rows: tuple = ()
        self.failure: BaseException | None = None
        self.produced: list = []

    def start_on(self, gear_class: str, rows) -> None:
        self.gear_class, self.rows = gear_class, tuple(rows)
        self.start()

    def run(self) -> None:
        try:
            with rows_compiled_once():   # the check compiles every row; the instantiation reuses them
                check_rows(self.gear_class, list(self.rows))
                template = CompiledTemplate(Template(self.gear_class, 0, self.rows))
                if any("template_version" in row.inputs for row in template.rows):
                    raise EngineError("an imported row reads template_version (please report this)")
                self.produced = template.run(self.params).lines
        except BaseException as failure:   # raised again in the importing thread, by verdict()
            self.failure = failure

    def verdict(self, stored_rows: tuple) -> None:
        """The stored rows are the rows proved, and they give the file back."""
        if not self.is_alive() and not self.rows:
            raise EngineError("the rows of the import were never checked (please report this)")
        self.join()
        if self.failure is not None:
            raise self.failure
        if stored_rows != self.rows:
            raise EngineError(f"class {self.gear_class}: the stored rows differ from the rows imported; "
                              "nothing stored (another writer at the same moment?)")
        for number, (got, want) in enumerate(zip(self.produced, self.lines), start=1):
            if got != want:
                raise EngineError(f"{self.path} line {number}: the imported template gives {got!r}, not {want!r}; "
                                  "nothing stored (please report this line)")
        if len(self.produced) != len(self.lines):
            raise EngineError(f"{self.path}: the imported template gives {len(self.produced)} lines, not "
                              f"{len(self.lines)}; nothing stored (please report this)")
