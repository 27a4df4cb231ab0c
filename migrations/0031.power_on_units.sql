-- Issue 27 (adversary 27c): a Fanuc keeps G20/G21 as the last program left them: the clear state
-- at reset and M30 leaves the units (Fanuc G-code list note; CNC Concepts, "Repeat initialized
-- words at the beginning of all programs": a metric program run after an inch one reads 200.0 as
-- 200 inches). So the units are not a power-on fact a program may rely on: they leave power_on,
-- and a program that does not state G20/G21 is refused ("motion before G21 is stated").
UPDATE machine
   SET power_on = NULLIF(btrim(regexp_replace(power_on, 'G2[01]( |$)', '', 'g')), '')
 WHERE power_on ~ 'G2[01]';
ALTER TABLE machine
    DROP CONSTRAINT machine_power_on_check,
    ADD CONSTRAINT machine_power_on_check CHECK (power_on ~ '^G(18|40|9[0457-9])( G(18|40|9[0457-9]))*$');
