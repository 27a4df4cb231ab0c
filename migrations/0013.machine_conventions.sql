-- Machine conventions and setup (issue 14, design notes §7, reference §A7). Real hobbers
-- differ in the sense of their axes (a table turning clockwise seen from above, Z pointing
-- down), so the machine record states each direction relative to DIN 66217: X points from
-- the work axis toward the hob, Z up along the work axis, Y = Z × X, and A, B, C turn
-- right-handed about X, Y, Z. +1 agrees with DIN 66217, -1 is the opposite sense. The
-- program's signs of A and of the B, Z and Y coupling terms follow these (a wrong sign cuts
-- the wrong hand of helix). X is not listed: it is the centre distance, positive toward the hob.
ALTER TABLE machine
    ADD COLUMN a_direction smallint NOT NULL DEFAULT 1 CHECK (a_direction IN (-1, 1)),
    ADD COLUMN b_direction smallint NOT NULL DEFAULT 1 CHECK (b_direction IN (-1, 1)),
    ADD COLUMN c_direction smallint NOT NULL DEFAULT 1 CHECK (c_direction IN (-1, 1)),
    ADD COLUMN y_direction smallint NOT NULL DEFAULT 1 CHECK (y_direction IN (-1, 1)),
    ADD COLUMN z_direction smallint NOT NULL DEFAULT 1 CHECK (z_direction IN (-1, 1)),
    -- The settable work offset the program selects (840D: G54…G57); it puts Z = 0 on the
    -- workpiece's top face and X = 0 on the work axis.
    ADD COLUMN work_offset text NOT NULL DEFAULT 'G54' CHECK (work_offset IN ('G54', 'G55', 'G56', 'G57')),
    -- The arbor or fixture below the blank: a cylinder of this diameter whose top lies
    -- fixture_gap mm below the blank's bottom face (0 = the blank sits on it). 0 = none.
    ADD COLUMN fixture_diameter numeric NOT NULL DEFAULT 0 CHECK (fixture_diameter >= 0),
    ADD COLUMN fixture_gap numeric NOT NULL DEFAULT 0 CHECK (fixture_gap >= 0),
    -- The tailstock (counter-holder) above the blank when clamped (M20): a cylinder of this
    -- diameter whose lowest point lies tailstock_gap mm above the top face. 0 = none.
    ADD COLUMN tailstock_diameter numeric NOT NULL DEFAULT 0 CHECK (tailstock_diameter >= 0),
    ADD COLUMN tailstock_gap numeric NOT NULL DEFAULT 0 CHECK (tailstock_gap >= 0),
    -- Where the hob goes at the end so the operator (or loader) can change the part; NULL =
    -- stay at the retract position.
    ADD COLUMN load_x numeric,
    ADD COLUMN load_z numeric,
    -- Rapid traverse (G0), mm/min: the cycle time, and the table speed a rapid Z move adds
    -- while Z is a leading axis of the coupling.
    ADD COLUMN rapid_rate numeric NOT NULL DEFAULT 5000 CHECK (rapid_rate > 0),
    -- Machines whose hob spindle must be oriented (SPOS) before the coupling is switched on.
    ADD COLUMN orient_before_coupling boolean NOT NULL DEFAULT false,
    -- The guard door's M functions (paper: 加工准备 opens and closes the door); NULL = none.
    ADD COLUMN door_close_m smallint CHECK (door_close_m BETWEEN 0 AND 999),
    ADD COLUMN door_open_m smallint CHECK (door_open_m BETWEEN 0 AND 999),
    ADD CONSTRAINT machine_load_position CHECK ((load_x IS NULL) = (load_z IS NULL));

-- The tool the program calls (T<n> D1): the hob's place in the machine's tool list.
ALTER TABLE hob ADD COLUMN tool_number integer NOT NULL DEFAULT 1 CHECK (tool_number BETWEEN 1 AND 32000);
