-- Issue 27: how a Fanuc-type lathe control reads a dimension word written without a decimal point
-- is a parameter of the control (Fanuc 0i/16i/18i parameter 3401#0 DPI; Mitsubishi #1078 Decpt2),
-- so the machine record states it. 'increment' (decimal point input type I, the default): X118 is
-- 118 least input increments, 0.118 mm, so the expander refuses such a word rather than guess;
-- 'calculator' (pocket-calculator type, type II): X118 is 118 mm, as X118. is.
-- power_on: the G codes the control is in at power-on and reset as its builder set its parameters
-- (Fanuc 3402: G18, G21/G20 by 0000#2, G99/G98 by 3402#4 FPM …), which a program that does not
-- state them runs under; NULL = not stated, and such a program is refused ("motion before G21 is
-- stated"). Only modal codes the ISO expander follows may be listed.
ALTER TABLE machine
    ADD COLUMN decimal_point_input text NOT NULL DEFAULT 'increment'
        CHECK (decimal_point_input IN ('increment', 'calculator')),
    ADD COLUMN power_on text
        CHECK (power_on ~ '^G(18|2[01]|40|9[0457-9])( G(18|2[01]|40|9[0457-9]))*$');
