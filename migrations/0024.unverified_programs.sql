-- Issue 17: a job of an imported class (engine instantiate --class) on a machine whose dialect the
-- verifier does not read, or whose program it refuses, may be stored with --unverified: the program
-- records that no verifier read it. The submission sets it (program_submission; store_program's
-- programs are verified); the lineage line says it, ` UNVERIFIED` appended after ` DRAFT`, and the
-- database holds the line to the column as it holds it to the rest of the record (migration 0015),
-- so a program is never marked one way and written the other. The engine never writes an unverified
-- program to a file for the machine. A hobbing program is proved by the simulation against its gear
-- and hob, so none is ever stored unverified. What reads as a lineage line (lineage_shaped,
-- migrations 0021, 0022) is unchanged: the word follows TEMPLATE, and a template row still never
-- writes such a line (check_program_lines).
ALTER TABLE program ADD COLUMN unverified boolean NOT NULL DEFAULT false;

CREATE FUNCTION program_lineage(program_id bigint, class_name text, version integer, template_hash text,
                                input_hash text, draft boolean, unverified boolean) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN program_lineage(program_id, class_name, version, template_hash, input_hash, draft)
       || CASE WHEN unverified THEN ' UNVERIFIED' ELSE '' END;

CREATE OR REPLACE VIEW program_submission AS
SELECT id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace, unverified FROM program
WHERE false;
ALTER VIEW program_submission ALTER COLUMN unverified SET DEFAULT false;

CREATE OR REPLACE FUNCTION submit_program() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    INSERT INTO program (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace,
                         unverified)
    VALUES (coalesce(NEW.id, nextval('program_id_seq')), NEW.job_id, NEW.gear_class, NEW.template_version,
            NEW.template_hash, NEW.name, NEW.lines, NEW.row_ids, NEW.trace, coalesce(NEW.unverified, false))
    RETURNING id INTO NEW.id;
    RETURN NEW;
END
$$;

-- check_program_release as in migration 0015, with the UNVERIFIED word and no unverified hobbing program.
CREATE OR REPLACE FUNCTION check_program_release() RETURNS trigger
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
