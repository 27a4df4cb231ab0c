-- The current schema, readable in one place. Migrations in ../migrations/ produce exactly
-- this (tests/test_migrations.py compares the catalogs). Change both together.

-- Core schema: gear classes, the module library (components + each class's assembly),
-- machines, hobs, gears, jobs and the programs instantiated from them.

-- The six control modules of the paper, in assembly order (design notes §4).
CREATE TABLE module_type (
    code     text PRIMARY KEY,
    position integer NOT NULL UNIQUE,
    title    text NOT NULL
);
INSERT INTO module_type (code, position, title) VALUES
    ('main',      1, 'main program: start, end, working-area limits'),
    ('prep',      2, 'preparation: positioning, swivel, tool, clamping'),
    ('sync',      3, 'synchronous motion: electronic gearbox coupling'),
    ('shift',     4, 'hob shift along its axis'),
    ('cutcond',   5, 'cutting conditions: spindle, coolant'),
    ('cutmotion', 6, 'cutting motion: infeed, axial pass, retract');

-- Group-technology tree of gear classes. Leaf classes carry templates.
CREATE TABLE gear_class (
    name             text PRIMARY KEY CHECK (name ~ '^[a-z][a-z0-9_]*$'),
    parent           text REFERENCES gear_class (name),
    description      text NOT NULL DEFAULT '',
    template_version integer NOT NULL DEFAULT 0 CHECK (template_version >= 0),
    -- The parameter values of the proven program the class was imported from (engine
    -- import-nc); lint checks the template's names against them. NULL: not imported.
    import_params    jsonb CHECK (jsonb_typeof(import_params) = 'object')
);

-- A component is the body of a template row (T, O, P_calc, S, P_emit). A body used by
-- several classes is stored once and referenced from each class's assembly.
CREATE TABLE component (
    id     bigserial PRIMARY KEY,
    t      text NOT NULL REFERENCES module_type (code),
    o      text,
    p_calc text,
    s      text,
    p_emit text,
    CONSTRAINT component_not_empty CHECK (nullif(btrim(o), '') IS NOT NULL
                                          OR nullif(btrim(s), '') IS NOT NULL)
);
-- Identity of a body: equal keys mean equal (t, o, p_calc, s, p_emit), NULLs included.
CREATE FUNCTION component_body_key(t text, o text, p_calc text, s text, p_emit text)
RETURNS text LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN md5(concat_ws(',', quote_literal(t), quote_nullable(o), quote_nullable(p_calc),
                     quote_nullable(s), quote_nullable(p_emit)));
CREATE INDEX component_body ON component (component_body_key(t, o, p_calc, s, p_emit));

-- A class's assembled template: row id (the paper's ID, evaluation order), module number N,
-- and the component that holds the row's body.
CREATE TABLE assembly (
    gear_class   text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    id           integer NOT NULL CHECK (id >= 0),
    n            integer NOT NULL DEFAULT 1 CHECK (n >= 0),
    component_id bigint NOT NULL REFERENCES component (id),
    PRIMARY KEY (gear_class, id)
);
CREATE INDEX assembly_component ON assembly (component_id);

-- Every class's assembled template as the paper's table (design notes §10).
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

-- Every class's assembled rows in one set-based statement (class_template suits one class).
CREATE VIEW assembled_row AS
WITH RECURSIVE lineage(gear_class, ancestor, depth) AS (
    SELECT g.name, g.name, 0 FROM gear_class g
    UNION ALL
    SELECT l.gear_class, g.parent, l.depth + 1
    FROM lineage l JOIN gear_class g ON g.name = l.ancestor
    WHERE g.parent IS NOT NULL AND l.depth < 50)
SELECT DISTINCT ON (l.gear_class, a.id) l.gear_class, a.id, a.n, a.component_id, a.gear_class AS owner
FROM lineage l JOIN assembly a ON a.gear_class = l.ancestor
ORDER BY l.gear_class, a.id, l.depth;

CREATE VIEW template_view AS
WITH body_use AS (
    SELECT component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit) AS body,
           count(DISTINCT a.gear_class)::integer AS classes
    FROM assembled_row a JOIN component c ON c.id = a.component_id
    GROUP BY 1)
SELECT a.gear_class, a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit, u.classes AS shared_by,
       a.owner AS inherited_from
FROM assembled_row a
JOIN component c ON c.id = a.component_id
JOIN body_use u ON u.body = component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit);

-- Machines and their limits. No program exceeding a limit is stored or written.
CREATE TABLE machine (
    name            text PRIMARY KEY,
    kind            text NOT NULL CHECK (kind IN ('hobber', 'lathe')),
    dialect         text NOT NULL,
    x_min           numeric NOT NULL,
    x_max           numeric NOT NULL,
    y_min           numeric NOT NULL DEFAULT 0,
    y_max           numeric NOT NULL DEFAULT 0,
    z_min           numeric NOT NULL,
    z_max           numeric NOT NULL,
    spindle_max     numeric NOT NULL CHECK (spindle_max > 0),  -- hob spindle (hobber) or main spindle, r/min
    table_speed_max numeric,                                   -- r/min of C, hobbers only
    module_max      numeric,                                   -- mm, hobbers only
    CHECK (x_min < x_max AND y_min <= y_max AND z_min < z_max)
);

-- Hob library.
CREATE TABLE hob (
    id             text PRIMARY KEY,
    module         numeric NOT NULL CHECK (module > 0),
    pressure_angle numeric NOT NULL DEFAULT 20 CHECK (pressure_angle > 0 AND pressure_angle < 45),
    starts         integer NOT NULL CHECK (starts > 0),
    tip_diameter   numeric NOT NULL CHECK (tip_diameter > 0),
    length         numeric NOT NULL CHECK (length > 0),
    hand           text NOT NULL CHECK (hand IN ('L', 'R')),
    accuracy_class text NOT NULL,
    material       text NOT NULL DEFAULT 'HSS',
    coating        text NOT NULL DEFAULT '',
    -- A worm-wheel hob is made for its worm; it never cuts cylindrical gears, nor the reverse.
    purpose        text NOT NULL DEFAULT 'cylindrical' CHECK (purpose IN ('cylindrical', 'worm_wheel'))
);

-- Workpieces (design notes §9 columns).
CREATE TABLE gear (
    id             integer PRIMARY KEY CHECK (id > 0),
    gear_class     text REFERENCES gear_class (name),
    module         numeric NOT NULL CHECK (module > 0),
    teeth          integer NOT NULL CHECK (teeth > 0),
    pressure_angle numeric NOT NULL DEFAULT 20 CHECK (pressure_angle > 0 AND pressure_angle < 45),
    helix_angle    numeric NOT NULL DEFAULT 0 CHECK (helix_angle >= 0 AND helix_angle < 60),
    hand           text CHECK (hand IN ('L', 'R')),
    face_width     numeric NOT NULL CHECK (face_width > 0),
    tip_diameter   numeric CHECK (tip_diameter > 0),
    root_diameter  numeric CHECK (root_diameter > 0),
    cone_angle     numeric,
    crowning       numeric,
    material       text,
    hardness       numeric,
    quality_grade  integer CHECK (quality_grade BETWEEN 1 AND 12),
    quantity       integer CHECK (quantity > 0),
    CHECK (helix_angle = 0 OR hand IS NOT NULL),
    CONSTRAINT gear_cone_angle CHECK (cone_angle > -45 AND cone_angle < 45),
    CONSTRAINT gear_crowning CHECK (crowning >= 0 AND crowning < 1)
);

-- A job: one workpiece on one machine with every parameter its template needs, as computed
-- by the class's model (and possibly edited afterwards in SQL).
-- params: {"name": value}; module_params: {"cutmotion:1": {"name": value}} (scope of module T,N).
CREATE TABLE job (
    id            bigserial PRIMARY KEY,
    gear_id       integer REFERENCES gear (id),
    gear_class    text NOT NULL REFERENCES gear_class (name),
    machine       text NOT NULL REFERENCES machine (name),
    hob_id        text REFERENCES hob (id),
    params        jsonb NOT NULL CHECK (jsonb_typeof(params) = 'object'),
    module_params jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(module_params) = 'object'),
    created_at    timestamptz NOT NULL DEFAULT now(),
    -- the cutting data chosen for the job and where they came from; confirmed jobs become cases
    cutting       jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(cutting) = 'object'),
    confirmed_at  timestamptz
);
CREATE INDEX job_gear ON job (gear_id);

-- One row per instantiation: the result table (emitted lines, with the template row that
-- emitted each) and the template version and hash it came from.
CREATE TABLE program (
    id               bigserial PRIMARY KEY,
    job_id           bigint NOT NULL REFERENCES job (id) ON DELETE CASCADE,
    gear_class       text NOT NULL REFERENCES gear_class (name),
    template_version integer NOT NULL,
    template_hash    text NOT NULL,
    name             text NOT NULL,
    lines            text[] NOT NULL,
    row_ids          integer[] NOT NULL,
    created_at       timestamptz NOT NULL DEFAULT now(),
    CHECK (cardinality(lines) = cardinality(row_ids))
);
CREATE INDEX program_job ON program (job_id);

-- The paper's result table, one row per emitted NC line.
CREATE VIEW result_line AS
SELECT p.id AS program_id, l.line_no::integer AS line_no, p.row_ids[l.line_no] AS template_row_id,
       l.text
FROM program p,
     unnest(p.lines) WITH ORDINALITY AS l (text, line_no);

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
