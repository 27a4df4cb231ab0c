"""Turning jobs from DXF drawings (design notes §8): tool paths, the turning model that
turns a job's parameters into the moves its template prints, plots."""
