-- Issue 33: several plants, one template authority. The head office publishes its released
-- template versions to every plant by PostgreSQL's logical replication; each plant publishes its
-- own history (jobs, programs, requests, drawings) back. docs/design.md §12 has the architecture.

-- template_version_rows: whether the version was released, set once by release_template and never
-- cleared, so a publication can filter on it (a version retired later still passes the filter and is
-- never deleted at a plant). A row filter on UPDATE reads only replica-identity columns: the
-- identity is a unique index holding it (FULL would hold the generated columns, which PostgreSQL 18
-- refuses as unpublished).
ALTER TABLE template_version_rows ADD COLUMN released boolean NOT NULL DEFAULT false;
CREATE UNIQUE INDEX template_version_rows_released ON template_version_rows (gear_class, version, released);
ALTER TABLE template_version_rows REPLICA IDENTITY USING INDEX template_version_rows_released;

-- refuse_changing_a_version: a version's rows are a record; only released may be set, once.
CREATE FUNCTION refuse_changing_a_version() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    IF TG_OP = 'UPDATE' AND NOT OLD.released AND NEW.released
       AND to_jsonb(NEW) - '{released,hash,row_ids}'::text[] = to_jsonb(OLD) - '{released,hash,row_ids}'::text[] THEN
        RETURN NEW;
    END IF;
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (a new version is stored when a '
                    'template changes; only its release is marked, once)', TG_OP, TG_TABLE_NAME
        USING ERRCODE = 'insufficient_privilege';
END
$$;

DROP TRIGGER template_version_rows_is_a_record ON template_version_rows;
CREATE TRIGGER template_version_rows_is_a_record BEFORE UPDATE OR DELETE ON template_version_rows
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_version();

UPDATE template_version_rows v SET released = true
FROM template_release r
WHERE r.gear_class = v.gear_class AND r.version = v.version AND NOT v.released;

-- release_template: the released version's rows are marked released (after the release row).
CREATE OR REPLACE FUNCTION release_template(class_name text, expected_version integer, expected_hash text,
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
    UPDATE template_version_rows v SET released = true
    WHERE v.gear_class = class_name AND v.version = current AND NOT v.released;
    RETURN made;
END
$$;

-- plant_identity: which plant this database is (one row, written by `engine plant subscribe`);
-- no row: the head office, or a shop of one database (plant 0).
CREATE TABLE plant_identity (
    one        boolean PRIMARY KEY DEFAULT true CHECK (one),
    number     integer NOT NULL CHECK (number BETWEEN 1 AND 9999),
    set_at     timestamptz NOT NULL DEFAULT now(),
    set_by     text NOT NULL DEFAULT session_user
);

-- This database's plant number: 0 at the head office.
CREATE FUNCTION plant_number() RETURNS integer
LANGUAGE sql STABLE
RETURN coalesce((SELECT p.number FROM plant_identity p), 0);

-- The ids a plant makes: [number * 10^10, (number + 1) * 10^10), the head office's from 1.
CREATE FUNCTION plant_first_id(number integer) RETURNS bigint
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN greatest(number::bigint * 10000000000, 1);

CREATE FUNCTION plant_last_id(number integer) RETURNS bigint
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN (number::bigint + 1) * 10000000000 - 1;

-- check_plant_id: a row made here has an id of this plant's range.
CREATE FUNCTION check_plant_id() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
DECLARE
    here integer := plant_number();
BEGIN
    IF NEW.id NOT BETWEEN plant_first_id(here) AND plant_last_id(here) THEN
        RAISE EXCEPTION '% %: plant % makes ids % to % only, so no two plants make one id; its sequence %_id_seq '
                        'was moved, run engine plant status', TG_TABLE_NAME, NEW.id, here, plant_first_id(here),
                        plant_last_id(here), TG_TABLE_NAME
            USING ERRCODE = 'check_violation', COLUMN = 'id';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER a_plant_id BEFORE INSERT ON job FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON program FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON program_request FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON drawing FOR EACH ROW EXECUTE FUNCTION check_plant_id();

-- refuse_at_a_plant: the head office's tables are read-only at a plant.
CREATE FUNCTION refuse_at_a_plant() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    IF plant_number() > 0 THEN
        RAISE EXCEPTION 'this database is plant %: % is the head office''s (templates are edited, released and '
                        'kept there, and replicated here); make the change at the head office', plant_number(),
                        TG_TABLE_NAME
            USING ERRCODE = 'read_only_sql_transaction';
    END IF;
    RETURN NULL;
END
$$;

CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON gear_class
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON component
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON assembly
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_version_rows
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_release
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_test
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON machine
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON hob
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON work_holding
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
