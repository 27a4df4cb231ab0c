-- Release control (issue 15, design notes §10): templates are drafted, tested and released; the
-- shop floor runs released versions only.
--
-- * Every committed change of a class's assembled template is a stored version (migration 0010).
--   The class's current version is its draft until it is released: a class has at most one draft,
--   created by the first change after a release. Older unreleased versions are superseded drafts.
-- * template_release records each release: who, when, the version and its hash, the tests the
--   gate ran and the impact it showed. Only engine_releaser (and the owner) may release, through
--   release_template. Releases are records nobody rewrites. The latest release of a class is the
--   version runners get; earlier releases are retired.
-- * A parent's change bumps its children's versions too (their assembled templates change), so
--   they get drafts of their own; their released versions stay until they are released.
-- * A program records whether it was made from a draft (set here, not by the caller). Only a role
--   that edits templates (engine_editor) may store a draft program, and only from the latest
--   release may anyone else store one.
-- * Every program carries its lineage: one line, written by the engine (row id -1, not a template
--   row), `; PROGRAM <id> TEMPLATE <class> v<version> <hash8> INPUT <hash8>` (or in parentheses,
--   the ISO comment), ` DRAFT` appended for a draft. INPUT is job_input_hash of the job's stored
--   parameters. The database checks the line against the program and its job.
-- * template_test holds the golden tests of the templates (engine test).

-- The role that releases (NOLOGIN, cluster-wide: created once, whichever database migrates first).
DO $$
BEGIN
    IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'engine_releaser') THEN
        BEGIN
            CREATE ROLE engine_releaser NOLOGIN;
        EXCEPTION WHEN duplicate_object OR unique_violation THEN
            NULL;   -- created meanwhile by a migration of another database
        END;
    END IF;
END
$$;
GRANT USAGE ON SCHEMA public TO engine_releaser;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_releaser;
GRANT SELECT ON ALL SEQUENCES IN SCHEMA public TO engine_releaser;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_releaser;

-- --- releases -------------------------------------------------------------------------------------

-- tests: the golden tests the gate ran, [{"class", "name", "passed"}]; impact: the gate's summary
-- ({"jobs", "changed", ...}); checks: what else the gate checked (lint, static analysis).
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
    FOREIGN KEY (gear_class, version, hash) REFERENCES template_version_rows (gear_class, version, hash)
        ON DELETE CASCADE,
    UNIQUE (gear_class, version)
);
CREATE INDEX template_release_class ON template_release (gear_class, id);

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

-- Release the class's current version (its draft): the gate's findings are recorded with it.
-- `expected_hash` is the hash of the rows the gate checked: if the draft changed since, nothing
-- is released. Returns the release's id.
CREATE FUNCTION release_template(class_name text, expected_version integer, expected_hash text,
                                 tests jsonb DEFAULT '[]', impact jsonb DEFAULT '{}', checks jsonb DEFAULT '{}',
                                 note text DEFAULT NULL)
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
    INSERT INTO template_release (gear_class, version, hash, role, tests, impact, checks, note)
    VALUES (class_name, current, stored, template_editor(), coalesce(tests, '[]'), coalesce(impact, '{}'),
            coalesce(checks, '{}'), note)
    RETURNING id INTO made;
    RETURN made;
END
$$;

REVOKE EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text) TO engine_releaser;
GRANT SELECT ON template_release, template_version_state, released_template_view
    TO engine_reader, engine_runner, engine_editor, engine_releaser;

-- Templates were live before release control: every class's current version is released now,
-- so runners keep getting what they got.
SELECT store_current_version(g.name) FROM gear_class g
WHERE NOT EXISTS (SELECT 1 FROM template_version_rows v WHERE v.gear_class = g.name AND v.version = g.template_version);
INSERT INTO template_release (gear_class, version, hash, released_by, role, note)
SELECT v.gear_class, v.version, v.hash, session_user, current_user,
       'released by migration 0015: the template was live before release control'
FROM template_version_rows v JOIN gear_class g ON g.name = v.gear_class AND g.template_version = v.version;

-- --- golden tests ---------------------------------------------------------------------------------

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
GRANT SELECT ON template_test TO engine_reader, engine_runner, engine_editor, engine_releaser;
GRANT INSERT, UPDATE, DELETE ON template_test TO engine_editor;
GRANT USAGE ON SEQUENCE template_test_id_seq TO engine_editor;

-- --- programs: draft or released, and their lineage ------------------------------------------------

-- The hash of a job's parameters that a program's lineage line shows (16 hex digits; the line
-- shows 8): sha256 of jsonb's own text of [params, module_params].
CREATE FUNCTION job_input_hash(params jsonb, module_params jsonb) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN left(encode(sha256(convert_to(jsonb_build_array(coalesce(params, '{}'), coalesce(module_params, '{}'))::text,
                                     'UTF8')), 'hex'), 16);

-- The lineage line's words (the engine writes them as an 840D comment `; …` or an ISO one `(…)`).
CREATE FUNCTION program_lineage(program_id bigint, class_name text, version integer, template_hash text,
                                input_hash text, draft boolean) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN format('PROGRAM %s TEMPLATE %s v%s %s INPUT %s', program_id, class_name, version, left(template_hash, 8),
              left(input_hash, 8)) || CASE WHEN draft THEN ' DRAFT' ELSE '' END;

ALTER TABLE program ADD COLUMN draft boolean NOT NULL DEFAULT false,
                    ADD COLUMN input_hash text;
CREATE INDEX program_input_hash ON program (left(input_hash, 8));
CREATE INDEX program_template_hash ON program (left(template_hash, 8));

-- Run after check_program (trigger names fire in alphabetical order: check_program, then this).
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
    SELECT job_input_hash(j.params, j.module_params) INTO NEW.input_hash FROM job j WHERE j.id = NEW.job_id;
    words := program_lineage(NEW.id, NEW.gear_class, NEW.template_version, NEW.template_hash, NEW.input_hash,
                             NEW.draft);
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

-- check_program as in migration 0010, but the lineage line's row id -1 (the engine's, not a template
-- row) is allowed.
CREATE OR REPLACE FUNCTION check_program() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    job_class text;
    stored record;
BEGIN
    NEW.stored_by := session_user;
    NEW.stored_role := template_editor();
    NEW.created_at := now();
    IF NEW.id > (SELECT last_value FROM program_id_seq) THEN
        RAISE EXCEPTION 'program %: its id was not drawn from program_id_seq', NEW.id
            USING ERRCODE = 'check_violation', COLUMN = 'id';
    END IF;
    SELECT j.gear_class INTO job_class FROM job j WHERE j.id = NEW.job_id;
    IF NOT FOUND OR job_class IS DISTINCT FROM NEW.gear_class THEN
        RAISE EXCEPTION 'program % for job %: %', NEW.name, NEW.job_id,
                        CASE WHEN job_class IS NULL THEN 'the job does not exist'
                             ELSE format('the job is of class %s, the program says %s', job_class, NEW.gear_class) END
            USING ERRCODE = 'foreign_key_violation', COLUMN = 'job_id';
    END IF;
    SELECT v.hash, v.row_ids INTO stored FROM template_version_rows v
    WHERE v.gear_class = NEW.gear_class AND v.version = NEW.template_version;
    IF NOT FOUND AND NEW.template_version = (SELECT template_version FROM gear_class WHERE name = NEW.gear_class) THEN
        PERFORM store_current_version(NEW.gear_class);   -- made in this transaction: fixed from now on
        SELECT v.hash, v.row_ids INTO stored FROM template_version_rows v
        WHERE v.gear_class = NEW.gear_class AND v.version = NEW.template_version;
    END IF;
    IF stored.hash IS DISTINCT FROM NEW.template_hash THEN
        RAISE EXCEPTION 'program % for job %: class % version % %; a program records the template it was made '
                        'from: make programs with the engine', NEW.name, NEW.job_id, NEW.gear_class,
                        NEW.template_version,
                        CASE WHEN stored.hash IS NULL THEN 'is not a stored version'
                             ELSE format('has hash %s, not %s', stored.hash, NEW.template_hash) END
            USING ERRCODE = 'foreign_key_violation', COLUMN = 'template_hash';
    END IF;
    IF cardinality(NEW.lines) = 0 OR array_ndims(NEW.lines) <> 1 OR array_lower(NEW.lines, 1) <> 1
       OR array_position(NEW.lines, NULL) IS NOT NULL OR array_position(NEW.row_ids, NULL) IS NOT NULL THEN
        RAISE EXCEPTION 'program % for job %: lines must be a list of one or more texts, each with its row id',
                        NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    IF NOT NEW.row_ids <@ (stored.row_ids || -1) THEN
        RAISE EXCEPTION 'program % for job %: row ids % are not rows of class % version %', NEW.name, NEW.job_id,
                        ARRAY(SELECT DISTINCT r FROM unnest(NEW.row_ids) r WHERE r <> ALL (stored.row_ids || -1) ORDER BY r),
                        NEW.gear_class, NEW.template_version
            USING ERRCODE = 'check_violation', COLUMN = 'row_ids';
    END IF;
    IF array_to_string(NEW.lines, '') ~ '[\x01-\x1f\x7f-\x9f\u2028\u2029]' THEN
        RAISE EXCEPTION 'program % for job %: line % holds a control character (CR, LF, TAB, ...); a line is one '
                        'block', NEW.name, NEW.job_id,
                        (SELECT min(l.number) FROM unnest(NEW.lines) WITH ORDINALITY AS l (text, number)
                         WHERE l.text ~ '[\x01-\x1f\x7f-\x9f\u2028\u2029]')
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    IF NEW.trace IS NOT NULL AND jsonb_typeof(NEW.trace) <> 'object' THEN
        RAISE EXCEPTION 'program % for job %: the trace must be a JSON object', NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'trace';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program_release BEFORE INSERT ON program
FOR EACH ROW EXECUTE FUNCTION check_program_release();
