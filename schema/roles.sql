-- schema/roles.sql: who may do what (loaded last: it grants on the objects of every other file).
-- Four NOLOGIN groups, granted to login roles: engine_reader reads; engine_runner makes jobs,
-- programs and cases; engine_editor changes templates; engine_releaser releases them. Writes go
-- through the engine's functions and views (SECURITY DEFINER: checked, versioned, audited), not
-- the tables; the owner (the role running `engine db migrate`) is the only other writer.

-- Roles belong to the cluster, not to this database: create them once, whichever database
-- migrates first, even concurrently.
DO $$
DECLARE
    role_name text;
BEGIN
    FOREACH role_name IN ARRAY ARRAY['engine_reader', 'engine_runner', 'engine_editor', 'engine_releaser'] LOOP
        IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = role_name) THEN
            BEGIN
                EXECUTE format('CREATE ROLE %I NOLOGIN', role_name);
            EXCEPTION WHEN duplicate_object OR unique_violation THEN
                NULL;   -- created meanwhile by a migration of another database
            END;
        END IF;
    END LOOP;
END
$$;

-- Everybody reads every table and view, also those a later migration adds (default privileges
-- of the role running the migrations), except the per-transaction change markers, which only
-- engine_releaser may read (it was granted every table after they were made; nothing to hide).
-- Sequences are no tables to default privileges: the first ones are readable, later ones only by
-- whoever draws ids from them.
GRANT USAGE ON SCHEMA public TO engine_reader, engine_runner, engine_editor;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_reader, engine_runner, engine_editor;
GRANT SELECT ON SEQUENCE component_id_seq, cutting_case_id_seq, job_id_seq, program_id_seq, template_audit_id_seq
    TO engine_reader, engine_runner, engine_editor, engine_releaser;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_reader, engine_runner, engine_editor;
-- Functions that write run only inside the engine's own functions, or are granted below.
REVOKE EXECUTE ON FUNCTION audit_class_change(text, jsonb, integer[]), bump_template_versions(text),
    component_for(text, text, text, text, text), delete_component_if_unused(bigint), note_template_change(text[]),
    store_current_version(text), replace_class_template(text, jsonb),
    store_program(bigint, text, integer, text, text, text[], integer[], jsonb), confirm_job_cases(bigint)
    FROM PUBLIC;
-- template_change and template_check_due are written by the versioning functions only.
REVOKE ALL ON template_change, template_check_due FROM engine_reader, engine_runner, engine_editor;
GRANT USAGE ON SCHEMA public TO engine_releaser;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_releaser;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_releaser;

-- Runners instantiate: jobs (and their parameters, edited to make a program again) and programs
-- through store_program / program_submission; confirming a job adds its cuts to the machining
-- history through confirm_job_cases. The nightly refactor (an unattended job, run as
-- engine_runner) writes the near-duplicate pairs it reported.
GRANT INSERT ON job TO engine_runner;
GRANT UPDATE (params, module_params, cutting) ON job TO engine_runner;
GRANT USAGE ON SEQUENCE job_id_seq, program_id_seq TO engine_runner;
GRANT EXECUTE ON FUNCTION store_program(bigint, text, integer, text, text, text[], integer[], jsonb),
    confirm_job_cases(bigint) TO engine_runner;
GRANT INSERT ON program_submission TO engine_runner;
-- Runners import drawings (engine import-dxf): they insert drawing records, never change them.
GRANT INSERT ON drawing TO engine_runner;
GRANT USAGE ON SEQUENCE drawing_id_seq TO engine_runner;
GRANT INSERT, UPDATE (last_seen) ON near_duplicate_seen TO engine_runner;

-- Editors change templates through template_view (audited, versioned) and the engine's imports
-- (replace_class_template); they create, describe and re-parent classes (re-parenting is
-- versioned and audited), set an imported class's import_params and line layout, write golden
-- tests, and mark near-duplicate pairs intended (and withdraw marks). Not the library tables,
-- programs, jobs, cases or the audit trail.
GRANT INSERT, UPDATE, DELETE ON template_view TO engine_editor;
GRANT INSERT (name, parent, description), UPDATE (parent, description, import_params) ON gear_class TO engine_editor;
GRANT UPDATE (line_ending, final_newline) ON gear_class TO engine_editor;
GRANT EXECUTE ON FUNCTION replace_class_template(text, jsonb) TO engine_editor;
GRANT INSERT, UPDATE, DELETE ON template_test TO engine_editor;
GRANT USAGE ON SEQUENCE template_test_id_seq TO engine_editor;
GRANT INSERT (pair_key, t, a, b, why), UPDATE (withdrawn_at) ON near_duplicate_intended TO engine_editor;
GRANT USAGE ON SEQUENCE near_duplicate_intended_id_seq TO engine_editor;

-- Releasers release: release_template records the gate's findings, as its caller states them, with
-- the release (and how the caller says it released; screens re-check it, docs/design.md §10).
REVOKE EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) TO engine_releaser;
