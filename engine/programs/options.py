"""How a run of `engine instantiate` goes, as two small objects its entry points take.

`Output` says where the program files go and whether existing ones are replaced; `RunMode` says
which template version runs, whether anything is stored, and how a batch behaves. The job's
own choices (cuts, feeds, coolant, ...) are engine.hobbing.choices.Choices. The command line
builds both from its options (engine.cli.instantiate) and hands them down through
engine.programs.instantiate, .remake and .class_jobs unchanged; they refuse nothing themselves:
the entry points and the command say which combinations are refused, as before.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import msgspec

Progress = Callable[[str, int, int], None]   # progress(stage, done, total) as a batch's items are planned
PLANNING = "planning"   # the stage a batch's progress callback is told while its gears are planned


class Output(msgspec.Struct, frozen=True):
    """Where a run writes its .MPF files, after its programs are committed.

    out: the file or folder (--out, or the config file's folder for the machine); a batch writes
        into it as a folder, one program into it if it is a folder or ends with the path
        separator, else to it as the file. None: no file, the program is only stored and printed.
    force: replace files that already exist at out; without it an existing file refuses the run
        and nothing is stored (an operator's file on the control is never overwritten unasked).
    mkdir: create out's folder (and the folders above it) if it does not exist; without it a
        missing folder refuses the run and nothing is stored (issue 31: a typo in a network
        share's path made a folder of programs nobody found).
    """
    out: str | Path | None = None
    force: bool = False
    mkdir: bool = False


class RunMode(msgspec.Struct, frozen=True):
    """How a run goes, apart from the job's choices and its files.

    draft: run the classes' drafts (an editor trying a change), not their released templates;
        the program is recorded as a draft.
    dry_run: compute and check as a stored run does, inside a READ ONLY transaction rolled back:
        nothing stored, no sequence advanced, no file written (engine.programs.batches).
    skip_bad: a batch stores its good programs and lists the bad gears or jobs skipped; without
        it any bad one stores nothing. Batches only.
    workers: processes that plan a batch of gears (engine.programs.workers); 1 plans in this
        process. Batches of gears only.
    progress: told progress(stage, done, total) as a batch's gears or jobs are planned; None
        tells nobody. Batches only.
    """
    draft: bool = False
    dry_run: bool = False
    skip_bad: bool = False
    workers: int = 1
    progress: Progress | None = None


NO_FILE = Output()       # the entry points' default: stored (and printed by the command), no file written
NORMAL_RUN = RunMode()   # the entry points' default: released templates, stored, a batch all or none, one process
