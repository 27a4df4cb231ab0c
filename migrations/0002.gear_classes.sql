-- Every gear class (issue 3): class inheritance of template rows, multi-unit gears,
-- hob purpose, the machining history for case-based cutting data, cutting data per job.

-- A class inherits its parent's assembled rows and adds (or overrides, by row id) only
-- what differs: a duplex class derives from its unit class. Inner nodes of the
-- group-technology tree have no rows, so for them this changes nothing.
CREATE FUNCTION class_template(class_name text)
RETURNS TABLE (id integer, n integer, component_id bigint, owner text)
LANGUAGE sql STABLE
AS $$
    WITH RECURSIVE lineage(name, parent, depth) AS (
        SELECT g.name, g.parent, 0 FROM gear_class g WHERE g.name = class_name
        UNION ALL
        SELECT g.name, g.parent, l.depth + 1
        FROM gear_class g JOIN lineage l ON g.name = l.parent
        WHERE l.depth < 50)
    SELECT DISTINCT ON (a.id) a.id, a.n, a.component_id, a.gear_class
    FROM lineage l JOIN assembly a ON a.gear_class = l.name
    ORDER BY a.id, l.depth
$$;

DROP VIEW template_view;
CREATE VIEW template_view AS
WITH assembled AS (
    SELECT g.name AS gear_class, r.id, r.n, r.component_id, r.owner
    FROM gear_class g CROSS JOIN LATERAL class_template(g.name) r),
body_use AS (
    SELECT component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit) AS body,
           count(DISTINCT a.gear_class)::integer AS classes
    FROM assembled a JOIN component c ON c.id = a.component_id
    GROUP BY 1)
SELECT a.gear_class, a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit, u.classes AS shared_by,
       a.owner AS inherited_from
FROM assembled a
JOIN component c ON c.id = a.component_id
JOIN body_use u ON u.body = component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit);

-- Further toothed units of a multi-unit (duplex) gear; unit 1 is the gear row itself.
-- One hob cuts all units, so module and pressure angle are the gear's.
CREATE TABLE gear_unit (
    gear_id       integer NOT NULL REFERENCES gear (id) ON DELETE CASCADE,
    unit          integer NOT NULL CHECK (unit >= 2),
    teeth         integer NOT NULL CHECK (teeth > 0),
    face_width    numeric NOT NULL CHECK (face_width > 0),
    tip_diameter  numeric CHECK (tip_diameter > 0),
    root_diameter numeric CHECK (root_diameter > 0),
    z_top         numeric NOT NULL CHECK (z_top < 0),   -- Z of the unit's upper face, mm
    PRIMARY KEY (gear_id, unit)
);

-- A worm-wheel hob is made for its worm; it never cuts cylindrical gears, nor the reverse.
ALTER TABLE hob ADD COLUMN purpose text NOT NULL DEFAULT 'cylindrical'
    CHECK (purpose IN ('cylindrical', 'worm_wheel'));

ALTER TABLE gear ADD CONSTRAINT gear_cone_angle CHECK (cone_angle > -45 AND cone_angle < 45);
ALTER TABLE gear ADD CONSTRAINT gear_crowning CHECK (crowning >= 0 AND crowning < 1);

-- The machining history: one case per cut of a proven job (paper §4).
CREATE TABLE cutting_case (
    id               bigserial PRIMARY KEY,
    module           numeric NOT NULL CHECK (module > 0),
    teeth            integer NOT NULL CHECK (teeth > 0),
    material         text NOT NULL,
    hardness         numeric,                                  -- HB
    quality_grade    integer CHECK (quality_grade BETWEEN 1 AND 12),
    hob_material     text NOT NULL,
    hob_coating      text NOT NULL DEFAULT '',
    hob_starts       integer NOT NULL CHECK (hob_starts > 0),
    hob_tip_diameter numeric NOT NULL CHECK (hob_tip_diameter > 0),
    cut              text NOT NULL CHECK (cut IN ('rough', 'finish')),
    hob_speed        numeric NOT NULL CHECK (hob_speed > 0),   -- r/min
    axial_feed       numeric NOT NULL CHECK (axial_feed > 0),  -- mm/min
    radial_feed      numeric NOT NULL CHECK (radial_feed > 0), -- mm/min
    source           text NOT NULL DEFAULT '',
    job_id           bigint REFERENCES job (id) ON DELETE SET NULL,
    created_at       timestamptz NOT NULL DEFAULT now()
);

-- The cutting data chosen for a job and where they came from; confirmed jobs become cases.
ALTER TABLE job ADD COLUMN cutting jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(cutting) = 'object');
ALTER TABLE job ADD COLUMN confirmed_at timestamptz;
