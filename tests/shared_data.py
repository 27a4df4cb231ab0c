"""Where the real files made by other people are (../shared/data: DXF drawings, NC programs).

SHARED_DATA_DIR if set; else a `shared/data` folder beside the project or above it; else the
workplace's /work/shared/data (a clean clone elsewhere, as CI makes, still finds it). Tests on
real files fail, never skip, when none is there."""
from __future__ import annotations

import os
from pathlib import Path

WORKPLACE_DATA = Path("/work/shared/data")


def shared_data() -> Path:
    if os.environ.get("SHARED_DATA_DIR"):
        return Path(os.environ["SHARED_DATA_DIR"])
    for folder in Path(__file__).resolve().parents:
        if (folder / "shared" / "data").is_dir():
            return folder / "shared" / "data"
    if WORKPLACE_DATA.is_dir():
        return WORKPLACE_DATA
    raise RuntimeError("no shared/data beside the project nor /work/shared/data: the real files are "
                       "missing; set SHARED_DATA_DIR")
