"""Where the real files made by other people are: tests/data of this repository (DXF drawings
in dxf/, NC programs in nc/), each listed with its origin and licence in the folder's
PROVENANCE.tsv (tests/data/README.md). They travel with the clone, so the tests that read them
run wherever the repository is checked out."""
from __future__ import annotations

from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data"


def shared_data() -> Path:
    """The folder of the real files (kept as a function: the tests call it by this name)."""
    return DATA
