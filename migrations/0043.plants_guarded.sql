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

-- replace_kept_row: at a plant, a row the head office made again replaces the one kept. Deletions
-- are not published (a plant's history refers to what it ran), so a hob, machine, work-holding,
-- golden test or unreleased class deleted at the head office stays at the plant; the head office's
-- new row of the same key (`engine hobs delete`, then `engine hobs add` of that id) then broke a
-- unique index there and stopped the plant's subscription, and with it every later release.
-- Enabled for replica only: it runs for the rows the replication applies, never for a person's write.
CREATE FUNCTION replace_kept_row() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    CASE TG_TABLE_NAME
        WHEN 'hob' THEN DELETE FROM hob WHERE upper(id) = upper(NEW.id);
        WHEN 'work_holding' THEN DELETE FROM work_holding WHERE upper(id) = upper(NEW.id);
        WHEN 'machine' THEN DELETE FROM machine WHERE name = NEW.name;
        WHEN 'gear_class' THEN DELETE FROM gear_class WHERE name = NEW.name;
        WHEN 'template_test' THEN
            DELETE FROM template_test WHERE id = NEW.id OR (gear_class, name) = (NEW.gear_class, NEW.name);
    END CASE;
    RETURN NEW;
END
$$;

CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON hob FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON work_holding
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON machine
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON template_test
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
ALTER TABLE hob ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE work_holding ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE machine ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE template_test ENABLE REPLICA TRIGGER made_again_at_the_head_office;

-- A class the head office made again under a deleted one's name (never released: see below).
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON gear_class
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
ALTER TABLE gear_class ENABLE REPLICA TRIGGER made_again_at_the_head_office;

-- refuse_deleting_a_released_class: at a head office (it publishes engine_templates), a class with a
-- release is not deleted. Its plants keep it and its released versions (deletions are not sent, a
-- plant's programs refer to them); a class made again under its name restarts at version 1, whose
-- release collided with the version 1 a plant kept and stopped that plant's subscription for good.
CREATE FUNCTION refuse_deleting_a_released_class() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    IF EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = OLD.name)
       AND EXISTS (SELECT 1 FROM pg_publication p WHERE p.pubname = 'engine_templates') THEN
        RAISE EXCEPTION 'class %: its released versions are kept at every plant, so a head office keeps the class; '
                        'make a class of another name instead', OLD.name
            USING ERRCODE = 'dependent_objects_still_exist';
    END IF;
    RETURN OLD;
END
$$;

CREATE TRIGGER released_classes_are_kept BEFORE DELETE ON gear_class
FOR EACH ROW EXECUTE FUNCTION refuse_deleting_a_released_class();

-- check_plant_id: its refusal names the constraint a_plant_id, so the engine tells it as a refusal (a
-- sequence moved by hand, exit 1) and not as an unexpected error.
CREATE OR REPLACE FUNCTION check_plant_id() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
DECLARE
    here integer := plant_number();
BEGIN
    IF NEW.id NOT BETWEEN plant_first_id(here) AND plant_last_id(here) THEN
        RAISE EXCEPTION '% %: plant % makes ids % to % only, so no two plants make one id; its sequence %_id_seq '
                        'was moved, run engine plant status', TG_TABLE_NAME, NEW.id, here, plant_first_id(here),
                        plant_last_id(here), TG_TABLE_NAME
            USING ERRCODE = 'check_violation', COLUMN = 'id', TABLE = TG_TABLE_NAME, CONSTRAINT = 'a_plant_id';
    END IF;
    RETURN NEW;
END
$$;
