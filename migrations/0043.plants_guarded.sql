-- Issue 33's adversary: what the replication between a head office and its plants relied on and
-- nobody enforced (docs/design.md §12).

-- `released` is the filter of the head office's publication: a version's rows reach every plant the
-- moment it is true. Only release_template sets it, after it recorded the release; the owner
-- setting it on a draft (or storing a draft with it) sent rows nobody released to every plant.
CREATE OR REPLACE FUNCTION refuse_changing_a_version() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    IF TG_OP = 'UPDATE' AND NOT OLD.released AND NEW.released
       AND to_jsonb(NEW) - '{released,hash,row_ids}'::text[] = to_jsonb(OLD) - '{released,hash,row_ids}'::text[]
       AND EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = NEW.gear_class AND r.version = NEW.version)
    THEN
        RETURN NEW;
    END IF;
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (a new version is stored when a '
                    'template changes; only release_template marks a version released, once, after recording '
                    'its release)', TG_OP, TG_TABLE_NAME
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE OR REPLACE FUNCTION check_version_rows() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    IF NEW.version IS DISTINCT FROM (SELECT template_version FROM gear_class WHERE name = NEW.gear_class)
       OR NEW.rows IS DISTINCT FROM (SELECT r.rows FROM assembled_rows_of(ARRAY[NEW.gear_class]) r) THEN
        RAISE EXCEPTION 'class % version %: a stored version holds the class''s current version and its rows '
                        'as they are; the engine stores them', NEW.gear_class, NEW.version
            USING ERRCODE = 'integrity_constraint_violation';
    END IF;
    IF NEW.released THEN
        RAISE EXCEPTION 'class % version %: a version is stored as a draft; release_template marks it released '
                        'when it records its release (engine template release)', NEW.gear_class, NEW.version
            USING ERRCODE = 'integrity_constraint_violation';
    END IF;
    SELECT g.line_ending, g.final_newline INTO NEW.line_ending, NEW.final_newline
    FROM gear_class g WHERE g.name = NEW.gear_class;
    RETURN NEW;
END
$$;
