-- Issue 30: the sign with which a Fanuc hobber's electronic gear box applies the helical
-- compensation of `G81 T_ L_ Q_ P_` (docs/reference/fanuc-egb.md §F4, §F5, §F7). The control turns
-- C by Z·sin P·360/(π·T·Q) degrees per mm of Z (metric input) for every Z move after G81; whether
-- it applies that with a plus or a minus sign, in the machine's C and Z senses, is not in the
-- retrieved manuals and is found by the dry run of §F5. egb_helix_sign states it: +1 the literal
-- reading (positive P, positive Z, positive C), -1 the opposite. NULL: not stated; the simulation
-- then refuses every helical gear's Fanuc program (it cannot tell which hand Q/P cuts). Existing
-- records are left unstated, as the shop has not yet run the dry run.
ALTER TABLE machine
    ADD COLUMN egb_helix_sign smallint CHECK (egb_helix_sign IN (-1, 1));
