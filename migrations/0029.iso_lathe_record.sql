-- Issue 27: real Fanuc/Haas lathe programs are followed by the ISO expander, which needs two facts
-- of the machine only its record can give. G28 returns to the reference point: reference_x
-- (diameter) and reference_z state it, in the frame the travel is stated in (the record's work
-- offset); NULL = not stated, and a program with G28 is refused. gcode_system says how the control
-- reads G90: 'A' (Fanuc's lathe default, Haas) has X/Z absolute and U/W incremental always, G90
-- being the turning cycle; 'B'/'C' select absolute with G90 (the engine's own programs state it);
-- NULL is read as 'B'.
ALTER TABLE machine
    ADD COLUMN reference_x numeric,
    ADD COLUMN reference_z numeric,
    ADD COLUMN gcode_system text CHECK (gcode_system IN ('A', 'B', 'C')),
    ADD CONSTRAINT machine_reference_point CHECK ((reference_x IS NULL) = (reference_z IS NULL));
UPDATE machine SET reference_x = x_max, reference_z = z_max, gcode_system = 'B'
WHERE name = 'lathe-iso' AND kind = 'lathe' AND dialect = 'iso';
