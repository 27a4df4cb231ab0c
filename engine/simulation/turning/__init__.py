"""The lathe's part of the simulation: it reads a lathe program's text (ISO or 840D) with the
verifier's reader and follows the tool through the blank and the finished part in the (z, r)
half-plane against the job's stored records and the machine (design notes §8). Entry points:
run.simulate_turning, run.prove_turning."""
from __future__ import annotations

# the job parameters that state a lathe program's blank (mm): here, not in .work, so the code that
# only names them (class jobs, a hobbing command's planner) does not load shapely (issue 28)
BLANK_PARAMS = ("stock_diameter", "stock_z_front", "stock_z_back")
