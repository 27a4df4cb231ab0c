"""Machines (design notes §6, §7): the record of a machine tool as the database holds it, below
the gears, the verifier and the models that all read it."""
