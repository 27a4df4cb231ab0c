-- schema/records.sql: the shop's records (after editing.sql): machines and their limits, the
-- hob library, workpieces, jobs (a workpiece on a machine with every parameter its template
-- needs) and the machining history that confirmed jobs add to. Programs are in programs.sql.

-- Machines and their limits. No program exceeding a limit is stored or written.
CREATE TABLE machine (
    name            text PRIMARY KEY,
    kind            text NOT NULL CHECK (kind IN ('hobber', 'lathe')),
    dialect         text NOT NULL,   -- with kind, the grammar the verifier reads programs with: hobber/840d,
                                     -- lathe/840d, lathe/iso (engine/programs/verifier/grammar.py); others make no program
    x_min           numeric NOT NULL,
    x_max           numeric NOT NULL,
    y_min           numeric NOT NULL DEFAULT 0,
    y_max           numeric NOT NULL DEFAULT 0,
    z_min           numeric NOT NULL,
    z_max           numeric NOT NULL,
    spindle_max     numeric NOT NULL CHECK (spindle_max > 0),  -- hob spindle (hobber) or main spindle, r/min
    table_speed_max numeric,                                   -- r/min of C, hobbers only
    module_max      numeric,                                   -- mm, hobbers only
    -- Conventions and setup (reference §A7): each axis's sense relative to
    -- DIN 66217 (+1 agrees, -1 opposite); the signs of A and of the coupling terms follow them.
    a_direction     smallint NOT NULL DEFAULT 1 CHECK (a_direction IN (-1, 1)),
    b_direction     smallint NOT NULL DEFAULT 1 CHECK (b_direction IN (-1, 1)),
    c_direction     smallint NOT NULL DEFAULT 1 CHECK (c_direction IN (-1, 1)),
    y_direction     smallint NOT NULL DEFAULT 1 CHECK (y_direction IN (-1, 1)),
    z_direction     smallint NOT NULL DEFAULT 1 CHECK (z_direction IN (-1, 1)),
    work_offset     text NOT NULL DEFAULT 'G54' CHECK (work_offset IN ('G54', 'G55', 'G56', 'G57')),
    fixture_diameter numeric NOT NULL DEFAULT 0 CHECK (fixture_diameter >= 0),  -- below the blank; 0 = none
    fixture_gap     numeric NOT NULL DEFAULT 0 CHECK (fixture_gap >= 0),        -- its top below the bottom face
    tailstock_diameter numeric NOT NULL DEFAULT 0 CHECK (tailstock_diameter >= 0),  -- above the blank; 0 = none
    tailstock_gap   numeric NOT NULL DEFAULT 0 CHECK (tailstock_gap >= 0),      -- its lowest point above the top face
    load_x          numeric,                                   -- the load position at the end; NULL = stay
    load_z          numeric,
    rapid_rate      numeric NOT NULL DEFAULT 5000 CHECK (rapid_rate > 0),       -- G0, mm/min
    orient_before_coupling boolean NOT NULL DEFAULT false,                      -- SPOS before EGON
    door_close_m    smallint CHECK (door_close_m BETWEEN 0 AND 999),            -- guard door M functions
    door_open_m     smallint CHECK (door_open_m BETWEEN 0 AND 999),
    -- ISO lathes (issue 27): the G28 reference point (X diameter, Z) in the travel's frame, NULL = not
    -- stated; the G-code system: 'A' X/Z absolute and U/W incremental, G90 a cycle; 'B'/'C' (NULL) G90 absolute.
    reference_x     numeric,
    reference_z     numeric,
    gcode_system    text CHECK (gcode_system IN ('A', 'B', 'C')),
    CONSTRAINT machine_reference_point CHECK ((reference_x IS NULL) = (reference_z IS NULL)),
    CHECK (x_min < x_max AND y_min <= y_max AND z_min < z_max),
    CONSTRAINT machine_safe_name CHECK (safe_name('machine', name)),
    CONSTRAINT machine_load_position CHECK ((load_x IS NULL) = (load_z IS NULL))
);

-- Hob library: the tools a hobbing job may use; a hob's id is printed in the program.
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
    purpose        text NOT NULL DEFAULT 'cylindrical' CHECK (purpose IN ('cylindrical', 'worm_wheel')),
    tool_number    integer NOT NULL DEFAULT 1 CHECK (tool_number BETWEEN 1 AND 32000),  -- T<n> D1
    CONSTRAINT hob_safe_id CHECK (safe_name('hob', id))
);
-- One hob per id whatever its case: H-M2-AA-R1 and h-m2-aa-r1 are one hob.
CREATE UNIQUE INDEX hob_id_ignoring_case ON hob (upper(id));

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
    -- The module stated is normal, or the worm's axial module m_x (worm wheels):
    -- m_n = m_x·cos γ. NULL = not stated: normal for cylindrical gears, refused for worm wheels.
    module_kind    text CHECK (module_kind IN ('normal', 'axial')),
    -- When the gear was stored (`engine gears list --since/--until`): set by the database on
    -- insert; an import that updates a gear keeps the first date. NULL for gears stored before
    -- dates were kept (their date is unknown, and no date is invented for them).
    created_at     timestamptz DEFAULT now(),
    -- The profile shift x (in modules), as the drawing gives it. The gear import checks the tip
    -- and root diameters of cylindrical gears against d = m_n·z/cos β, d_a = d + 2·m_n·(1 + x)
    -- and d_f = d − 2·m_n·(1.25 − x); NULL = not given (the diameters must then fit some plausible x).
    profile_shift  numeric CONSTRAINT gear_profile_shift CHECK (profile_shift > -2 AND profile_shift < 2),
    CHECK (helix_angle = 0 OR hand IS NOT NULL),
    CONSTRAINT gear_cone_angle CHECK (cone_angle > -45 AND cone_angle < 45),
    CONSTRAINT gear_crowning CHECK (crowning >= 0 AND crowning < 1)
);

-- A drawing as `engine import-dxf` read it (issue 26): what the turning proof takes the part, the
-- blank, the tool-change position and the materials from, never from job.params (which a runner
-- may edit in SQL). Written once with its job, never changed or deleted: importing the drawing
-- again (e.g. with another --material) makes a new record and a new job. profile: the segments as
-- job.params.profile holds them ([["line", z0, r0, z1, r1] | ["arc", z0, r0, z1, r1, zc, rc, ccw]],
-- mm); stock_diameter NULL: the blank the importer assumes (docs/design.md §8); workpiece_material
-- and tool_materials ({"n": material} per operation) NULL: the defaults. sha256 of the file's
-- bytes; NULL for the records migration 0027 made from jobs imported before it (imported_by
-- 'migration 0027'). threads: each THREAD operation's pitch and crest and root lines as the job's
-- module_params hold them ({"n": {"thread_pitch": p, "paths": [...]}}, {} for none; migration
-- 0028), NULL when not recorded (records no job names at 0028: the proof reads module_params).
CREATE TABLE drawing (
    id                 bigserial PRIMARY KEY,
    file_name          text NOT NULL,
    sha256             text CHECK (sha256 ~ '^[0-9a-f]{64}$'),
    units              text,
    profile            jsonb NOT NULL CHECK (jsonb_typeof(profile) = 'array'),
    stock_diameter     double precision CHECK (stock_diameter > 0),
    stock_z_front      double precision,
    stock_z_back       double precision,
    tool_change_x      double precision,
    tool_change_z      double precision,
    workpiece_material text,
    tool_materials     jsonb CHECK (tool_materials IS NULL OR jsonb_typeof(tool_materials) = 'object'),
    imported_by        text NOT NULL DEFAULT current_user,
    imported_at        timestamptz NOT NULL DEFAULT now(),
    threads            jsonb CHECK (threads IS NULL OR jsonb_typeof(threads) = 'object')
);
CREATE TRIGGER drawing_is_a_record BEFORE UPDATE OR DELETE ON drawing
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER drawing_is_not_truncated BEFORE TRUNCATE ON drawing
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

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
    confirmed_at  timestamptz,
    -- a turning job's drawing record (NULL: a hobbing job, or a class job without a drawing)
    drawing_id    bigint REFERENCES drawing (id),
    CONSTRAINT job_safe_params CHECK (job_params_safe(params, module_params))
);
CREATE INDEX job_gear ON job (gear_id);

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

-- Physically plausible cases, whoever adds them: finite values (numeric takes NaN and infinity),
-- a cutting speed v = π·d_a0·n0/1000 of at most 600 m/min (twice the fastest of reference §C,
-- carbide dry), feeds per workpiece revolution f = v_f/(n0·z0/z2) of at most 10·m_n (2.5 to 10
-- times the typical ranges of §C; the paper's suspicious 8.1 mm at m 2 stays in). Cases stored
-- before the rule are not re-checked (NOT VALID).
ALTER TABLE cutting_case ADD CONSTRAINT cutting_case_plausible CHECK (
    module < 'Infinity' AND hob_tip_diameter < 'Infinity' AND hob_speed < 'Infinity'
    AND axial_feed < 'Infinity' AND radial_feed < 'Infinity'
    AND (hardness IS NULL OR hardness > 0 AND hardness < 'Infinity')
    AND pi() * hob_tip_diameter * hob_speed / 1000 <= 600
    AND axial_feed * teeth <= 10 * module * hob_speed * hob_starts
    AND radial_feed * teeth <= 10 * module * hob_speed * hob_starts) NOT VALID;

-- A number of a job's cutting data, or NULL if it is not a positive finite number.
CREATE FUNCTION cutting_number(value jsonb) RETURNS numeric
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN CASE WHEN jsonb_typeof(value) = 'number' AND value::text::numeric > 0 THEN value::text::numeric END;

-- engine cases confirm: a job the engine made a program for, whose cutting data its machine can
-- run, joins the history, one case per cut kind of its stored cutting data. The case's values
-- are the job's; the hob speed is the one its last program ran (n0). Returns the new case ids.
CREATE FUNCTION confirm_job_cases(confirmed_job bigint) RETURNS bigint[]
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    found_job record;
    speed numeric;
    ran numeric;
    cut text;
    ids bigint[] := '{}';
    case_id bigint;
BEGIN
    SELECT j.cutting, j.confirmed_at, j.machine, g.id AS gear_id, g.module, g.teeth, g.material, g.hardness,
           g.quality_grade, h.material AS hob_material, h.coating, h.starts, h.tip_diameter, m.spindle_max,
           m.table_speed_max
    INTO found_job
    FROM job j LEFT JOIN gear g ON g.id = j.gear_id LEFT JOIN hob h ON h.id = j.hob_id
    JOIN machine m ON m.name = j.machine
    WHERE j.id = confirmed_job FOR UPDATE OF j;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'job % does not exist; nothing confirmed', confirmed_job USING ERRCODE = 'no_data_found';
    END IF;
    IF found_job.confirmed_at IS NOT NULL THEN
        RAISE EXCEPTION 'job % was already confirmed at %; its cases are in the history (engine cases list)',
                        confirmed_job, to_char(found_job.confirmed_at, 'YYYY-MM-DD HH24:MI')
            USING ERRCODE = 'check_violation';
    END IF;
    IF NOT (found_job.cutting ? 'rough' OR found_job.cutting ? 'finish') THEN
        RAISE EXCEPTION 'job % has no cutting data stored (job.cutting is empty); store the chosen cutting data '
                        'with the job before confirming it', confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    IF found_job.gear_id IS NULL OR found_job.tip_diameter IS NULL THEN
        RAISE EXCEPTION 'job % has no gear or no hob; only hobbing jobs become cutting cases', confirmed_job
            USING ERRCODE = 'check_violation';
    END IF;
    IF found_job.material IS NULL THEN
        RAISE EXCEPTION 'gear % of job % has no material; set it before confirming the job', found_job.gear_id,
                        confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    SELECT cutting_number(p.trace->'inputs'->'job'->'n0') INTO ran FROM program p
    WHERE p.job_id = confirmed_job ORDER BY p.id DESC LIMIT 1;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'job % has no stored program: only a job the engine made a program for becomes a case; '
                        'make it first (engine instantiate --job %)', confirmed_job, confirmed_job
            USING ERRCODE = 'check_violation';
    END IF;
    speed := cutting_number(found_job.cutting->'hob_speed');
    FOREACH cut IN ARRAY ARRAY['rough', 'finish'] LOOP
        CONTINUE WHEN NOT found_job.cutting ? cut;
        IF speed IS NULL OR cutting_number(found_job.cutting->cut->'axial_feed') IS NULL
           OR cutting_number(found_job.cutting->cut->'radial_feed') IS NULL THEN
            RAISE EXCEPTION 'job %: cutting data of the % cut need a positive hob_speed, axial_feed and radial_feed '
                            '(mm/min); fix job.cutting', confirmed_job, cut USING ERRCODE = 'check_violation';
        END IF;
    END LOOP;
    IF ran IS NULL THEN
        RAISE EXCEPTION 'job %: its last program does not record the hob speed it ran (no n0 in its trace), so '
                        'nothing vouches for job.cutting; make the program again (engine instantiate --job %)',
                        confirmed_job, confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    IF ran IS DISTINCT FROM speed THEN
        RAISE EXCEPTION 'job %: job.cutting says hob speed % r/min, but its last program ran n0 = % r/min; make the '
                        'program again from the job or fix job.cutting', confirmed_job, speed, ran
            USING ERRCODE = 'check_violation';
    END IF;
    IF speed > found_job.spindle_max THEN
        RAISE EXCEPTION 'job %: hob speed % r/min exceeds %''s hob spindle maximum % r/min; not a case',
                        confirmed_job, speed, found_job.machine, found_job.spindle_max
            USING ERRCODE = 'check_violation';
    END IF;
    IF speed * found_job.starts / found_job.teeth > found_job.table_speed_max THEN
        RAISE EXCEPTION 'job %: table speed % r/min exceeds %''s % r/min; not a case', confirmed_job,
                        round(speed * found_job.starts / found_job.teeth, 1), found_job.machine,
                        found_job.table_speed_max
            USING ERRCODE = 'check_violation';
    END IF;
    FOREACH cut IN ARRAY ARRAY['rough', 'finish'] LOOP
        CONTINUE WHEN NOT found_job.cutting ? cut;
        INSERT INTO cutting_case (module, teeth, material, hardness, quality_grade, hob_material, hob_coating,
                                  hob_starts, hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source, job_id)
        VALUES (found_job.module, found_job.teeth, found_job.material, found_job.hardness, found_job.quality_grade,
                found_job.hob_material, found_job.coating, found_job.starts, found_job.tip_diameter, cut, speed,
                cutting_number(found_job.cutting->cut->'axial_feed'),
                cutting_number(found_job.cutting->cut->'radial_feed'), format('job %s', confirmed_job), confirmed_job)
        RETURNING id INTO case_id;
        ids := ids || case_id;
    END LOOP;
    UPDATE job SET confirmed_at = now() WHERE id = confirmed_job;
    RETURN ids;
END
$$;
