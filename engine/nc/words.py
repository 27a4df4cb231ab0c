"""Limits of the NC words the engine writes and reads in every dialect."""
from __future__ import annotations

MAX_TOOL = 99   # two digits: ISO T0101 is tool 01, offset 01; 840D T1 D1
