-- Issue 29: a small gear met one fixture and one tailstock per machine (the machine record's
-- fixture_diameter, tailstock_diameter): 93 gears with a root under about Ø20.6 were refused,
-- though each is cut on a work-holding sized for the job (an arbor, small centres). The
-- work-holdings are a library like the hobs; a job names the one it is clamped on (NULL: the
-- machine record's fixture and tailstock, as before), its program states it (`; FIXTURE <id>`)
-- and the simulation proves the program against its solids.
CREATE TABLE work_holding (
    id                 text PRIMARY KEY,
    kind               text NOT NULL CHECK (kind IN ('arbor', 'mandrel', 'collet', 'centres')),
    -- the part under the gear the hob must clear: its diameter and height (mm), its top face the
    -- machine record's fixture_gap below the gear's bottom face; the machine's fixture below it
    diameter           numeric NOT NULL CHECK (diameter > 0 AND diameter < 'Infinity'),
    height             numeric NOT NULL CHECK (height > 0 AND height < 'Infinity'),
    -- the centre (or tailstock) above the top face, mm; 0 = none
    tailstock_diameter numeric NOT NULL DEFAULT 0 CHECK (tailstock_diameter >= 0 AND tailstock_diameter < 'Infinity'),
    machine            text REFERENCES machine (name),   -- the machine it fits; NULL = any hobber
    CONSTRAINT work_holding_safe_id CHECK (id ~ '^[A-Za-z0-9][A-Za-z0-9_.-]{0,31}$')
);
-- One work-holding per id whatever its case (a setter reading `; FIXTURE …` cannot tell them apart).
CREATE UNIQUE INDEX work_holding_id_ignoring_case ON work_holding (upper(id));

-- The work-holding a job is clamped on; NULL: the machine record's fixture and tailstock.
ALTER TABLE job ADD COLUMN work_holding_id text REFERENCES work_holding (id);
