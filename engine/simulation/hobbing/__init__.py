"""The hobbing machine's part of the simulation: it reads a hobbing program's text with the
verifier's reader and follows every axis block by block in the DIN 66217 frame against the gear,
the hob and the machine records (design notes §7). Entry points: run.simulate_program,
run.prove_program, stored.simulate_stored_program."""
