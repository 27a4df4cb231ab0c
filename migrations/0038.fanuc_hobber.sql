-- Issue 30: the Fanuc hobber's program-number rule (docs/reference/fanuc-egb.md §F7). A Fanuc
-- program is stored on the control under an O number, not a name: the hobbing templates write
-- `O<n> (GEAR<id>)` with n = program_number_base + the gear's id (O1042 for gear 42 at base
-- 1000), so the operator finds a gear's program by its number and the number never collides with
-- another gear's on that machine. The O number must lie in 1…99999 and outside O9000…O9999 (the
-- builder's macros, engine/verifier/grammar.py); a gear whose number falls outside is refused by
-- name. NULL: the record states no rule; a Fanuc hobber without one makes no program. The 840D
-- names its programs (%_N_GEAR42_MPF) and leaves it NULL. The units of Q and P without a decimal
-- point (§F7 egb_q_increment, egb_p_increment) are not added: the engine writes both with a point.
ALTER TABLE machine
    ADD COLUMN program_number_base integer CHECK (program_number_base BETWEEN 0 AND 99998);
