"""The lathe's part of the simulation: it reads a lathe program's text (ISO or 840D) with the
verifier's reader and follows the tool through the blank and the finished part in the (z, r)
half-plane against the job's stored records and the machine (design notes §8). Entry points:
run.simulate_turning, run.prove_turning."""
