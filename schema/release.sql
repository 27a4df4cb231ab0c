-- schema/release.sql: release control (after programs.sql). Editors change a class's template as
-- a draft version; runners get only the released version, which `engine template release`
-- (the gate: golden tests, impact, lint) makes; every program records whether it was made from a
-- draft. A release is a record, never changed. Also the golden tests the gate runs.

-- One row per release of a class's version, with what the gate found (engine template release).
-- tests: the golden tests the gate ran, [{"class", "name", "passed"}]; impact: the gate's summary
-- ({"jobs", "changed", ...}); checks: what else the gate checked (lint, static analysis). These
-- three are what the caller of release_template states: a screen never shows them as the gate's
-- result without re-running the recorded golden_tests (engine.release.recheck).
CREATE TABLE template_release (
    id          bigserial PRIMARY KEY,
    gear_class  text NOT NULL,
    version     integer NOT NULL,
    hash        text NOT NULL,
    released_at timestamptz NOT NULL DEFAULT now(),
    released_by text NOT NULL DEFAULT session_user,   -- the login person
    role        text NOT NULL,                        -- the role acting (template_editor())
    tests       jsonb NOT NULL DEFAULT '[]',
    impact      jsonb NOT NULL DEFAULT '{}',
    checks      jsonb NOT NULL DEFAULT '{}',
    note        text,
    -- how the releasing login says it released: engine (after the gate), seed, sql (by hand),
    -- unrecorded (before migration 0026); a claim, never a proof (docs/design.md §10)
    released_via text NOT NULL DEFAULT 'sql' CHECK (released_via IN ('engine', 'seed', 'sql', 'unrecorded')),
    -- the golden tests of the class and its descendants at the release, taken by the database
    -- (golden_tests_of); NULL before migration 0026
    golden_tests jsonb CHECK (golden_tests IS NULL OR jsonb_typeof(golden_tests) = 'array'),
    FOREIGN KEY (gear_class, version, hash) REFERENCES template_version_rows (gear_class, version, hash)
        ON DELETE CASCADE,
    UNIQUE (gear_class, version)
);
CREATE INDEX template_release_class ON template_release (gear_class, id);
-- Never changed; deleted only with its class (a cascade, run by a trigger).
CREATE TRIGGER template_release_is_a_record BEFORE UPDATE OR DELETE ON template_release
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER template_release_is_not_truncated BEFORE TRUNCATE ON template_release
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- The version runners get: the class's latest release (NULL if it was never released).
CREATE FUNCTION released_version(class_name text) RETURNS integer
LANGUAGE sql STABLE
RETURN (SELECT r.version FROM template_release r WHERE r.gear_class = class_name ORDER BY r.id DESC LIMIT 1);

-- Every stored version with its state: released (the latest release), retired (released before
-- it), draft (the class's current version, not released), superseded (an earlier draft).
CREATE VIEW template_version_state AS
SELECT v.gear_class, v.version, v.hash, v.created_at, v.created_by,
       CASE WHEN r.version IS NOT NULL AND v.version = released_version(v.gear_class) THEN 'released'
            WHEN r.version IS NOT NULL THEN 'retired'
            WHEN v.version = g.template_version THEN 'draft'
            ELSE 'superseded' END AS state,
       r.released_at, r.released_by, r.role AS released_role
FROM template_version_rows v
JOIN gear_class g ON g.name = v.gear_class
LEFT JOIN template_release r ON r.gear_class = v.gear_class AND r.version = v.version;

-- The rows runners get, one per template row, like template_view (read only).
CREATE VIEW released_template_view AS
SELECT v.gear_class, v.version, x.id, x.t, x.n, x.p_calc, x.s, x.o, x.p_emit
FROM template_release r
JOIN template_version_rows v ON v.gear_class = r.gear_class AND v.version = r.version
CROSS JOIN LATERAL jsonb_to_recordset(v.rows) AS x (id integer, t text, n integer, p_calc text, s text, o text,
                                                     p_emit text)
WHERE r.version = released_version(r.gear_class);

-- Release the class's current version (its draft): the gate's findings, as the caller states them,
-- are recorded with it. `expected_hash` is the hash of the rows the gate checked: if the draft
-- changed since, nothing is released. `via` is how the caller says it releases ('engine' after
-- the engine's gate, 'seed' for the shipped templates; 'sql', the default, by hand): a claim of
-- the releasing login, kept as such. The golden tests of the class and its descendants are taken
-- by the database itself (from template_test, each with its class's version now), so a screen can
-- re-run exactly what the gate ran. Returns the release's id.
CREATE FUNCTION release_template(class_name text, expected_version integer, expected_hash text,
                                 tests jsonb DEFAULT '[]', impact jsonb DEFAULT '{}', checks jsonb DEFAULT '{}',
                                 note text DEFAULT NULL, via text DEFAULT 'sql')
RETURNS bigint
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    current integer;
    stored text;
    made bigint;
BEGIN
    SELECT g.template_version INTO current FROM gear_class g WHERE g.name = class_name FOR UPDATE;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'gear class % does not exist; see engine template list', quote_nullable(class_name)
            USING ERRCODE = 'foreign_key_violation';
    END IF;
    IF current IS DISTINCT FROM expected_version THEN
        RAISE EXCEPTION 'class %: its draft is version % now, not the version % that was checked; nothing released, '
                        'run the release again', class_name, current, expected_version
            USING ERRCODE = 'serialization_failure';
    END IF;
    SELECT v.hash INTO stored FROM template_version_rows v WHERE v.gear_class = class_name AND v.version = current;
    IF NOT FOUND THEN
        PERFORM store_current_version(class_name);
        SELECT v.hash INTO stored FROM template_version_rows v WHERE v.gear_class = class_name AND v.version = current;
    END IF;
    IF stored IS DISTINCT FROM expected_hash THEN
        RAISE EXCEPTION 'class % version %: its rows have hash %, not the % that was checked; nothing released',
                        class_name, current, stored, expected_hash
            USING ERRCODE = 'serialization_failure';
    END IF;
    IF EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = class_name AND r.version = current) THEN
        RAISE EXCEPTION 'class % version % is released already; there is no draft to release', class_name, current
            USING ERRCODE = 'unique_violation';
    END IF;
    INSERT INTO template_release (gear_class, version, hash, role, tests, impact, checks, note, released_via,
                                  golden_tests)
    VALUES (class_name, current, stored, template_editor(), coalesce(tests, '[]'), coalesce(impact, '{}'),
            coalesce(checks, '{}'), note, coalesce(via, 'sql'), golden_tests_of(class_name))
    RETURNING id INTO made;
    RETURN made;
END
$$;

-- A program of a draft is made by an editor only (an editor's try, marked draft); a program of
-- a retired version is refused; a hobbing program is never unverified (the simulation proves it
-- against its gear and hob). Its lineage line (row id -1) must be the one line the database
-- computes from the record (program_lineage), so a program is never marked one way and written
-- the other. Fires after check_program and check_program_lines (trigger names in order).
CREATE FUNCTION check_program_release() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    released integer := released_version(NEW.gear_class);
    words text;
    lineage_lines text[];
BEGIN
    NEW.draft := NOT EXISTS (SELECT 1 FROM template_release r
                             WHERE r.gear_class = NEW.gear_class AND r.version = NEW.template_version);
    IF NEW.draft AND NOT pg_has_role(template_editor(), 'engine_editor', 'MEMBER') THEN
        RAISE EXCEPTION 'program % for job %: class % version % is a draft (released: %); only an editor '
                        '(engine_editor) tries a draft, runners make programs from the released version',
                        NEW.name, NEW.job_id, NEW.gear_class, NEW.template_version, coalesce(released::text, 'none')
            USING ERRCODE = 'insufficient_privilege', COLUMN = 'template_version';
    END IF;
    IF NOT NEW.draft AND NEW.template_version IS DISTINCT FROM released THEN
        RAISE EXCEPTION 'program % for job %: class % version % was retired by the release of version %; make '
                        'the program again', NEW.name, NEW.job_id, NEW.gear_class, NEW.template_version, released
            USING ERRCODE = 'check_violation', COLUMN = 'template_version';
    END IF;
    IF NEW.unverified AND EXISTS (SELECT 1 FROM job j JOIN machine m ON m.name = j.machine
                                  WHERE j.id = NEW.job_id AND m.kind = 'hobber') THEN
        RAISE EXCEPTION 'program % for job %: a hobbing program is proved by the simulation against its gear and '
                        'hob; it is never stored unverified', NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'unverified';
    END IF;
    SELECT job_input_hash(j.params, j.module_params) INTO NEW.input_hash FROM job j WHERE j.id = NEW.job_id;
    words := program_lineage(NEW.id, NEW.gear_class, NEW.template_version, NEW.template_hash, NEW.input_hash,
                             NEW.draft, NEW.unverified);
    lineage_lines := ARRAY(SELECT l.text FROM unnest(NEW.lines, NEW.row_ids) AS l (text, row_id) WHERE l.row_id = -1);
    IF lineage_lines IS DISTINCT FROM ARRAY['; ' || words] AND lineage_lines IS DISTINCT FROM ARRAY['(' || words || ')']
    THEN
        RAISE EXCEPTION 'program % for job %: its lineage line (row id -1) must be the one line "; %" (or "(%)"), '
                        'found %; make programs with the engine', NEW.name, NEW.job_id, words, words,
                        coalesce(array_to_string(lineage_lines, ' | '), 'none')
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program_release BEFORE INSERT ON program
FOR EACH ROW EXECUTE FUNCTION check_program_release();

-- A golden test of a class's template (engine test): the workpiece (a gear, or the job's
-- parameters as JSON), the job choices (engine instantiate's, as JSON), and what the program must
-- show: `expect`, one expectation per element (exact lines, patterns, numeric properties with a
-- tolerance; the language is engine.templates.golden's).
CREATE TABLE template_test (
    id          bigserial PRIMARY KEY,
    gear_class  text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    name        text NOT NULL CHECK (name ~ '^[A-Za-z0-9][A-Za-z0-9_.-]{0,79}$'),
    gear_id     integer REFERENCES gear (id),
    params      jsonb CHECK (params IS NULL OR jsonb_typeof(params) = 'object'),
    choices     jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(choices) = 'object'),
    expect      text[] NOT NULL CHECK (cardinality(expect) > 0),
    description text NOT NULL DEFAULT '',
    created_at  timestamptz NOT NULL DEFAULT now(),
    created_by  text NOT NULL DEFAULT session_user,
    UNIQUE (gear_class, name),
    CHECK ((gear_id IS NULL) <> (params IS NULL))
);

-- The golden tests of a class and its descendants as stored now, each with its class's current
-- version: what the gate ran, recorded with a release by the database (not by its caller).
CREATE FUNCTION golden_tests_of(class_name text) RETURNS jsonb
LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_agg(jsonb_build_object('id', t.id, 'class', t.gear_class, 'name', t.name,
                                                     'gear_id', t.gear_id, 'params', t.params, 'choices', t.choices,
                                                     'expect', to_jsonb(t.expect), 'description', t.description,
                                                     'version', g.template_version)
                                  ORDER BY t.gear_class, t.name), '[]')
        FROM classes_and_below(ARRAY[class_name]) b
        JOIN gear_class g ON g.name = b.name
        JOIN template_test t ON t.gear_class = g.name);
