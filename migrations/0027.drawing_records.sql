-- Issue 26: the turning proof reads records, never the plan. A turning job's finished part, blank,
-- tool-change position and materials were read from job.params, which a runner may edit in SQL
-- (a steel part declared aluminium runs at 1181 m/min; a shrunk profile lets a gouge pass). They
-- now live in a drawing record, written once by `engine import-dxf` in the transaction that stores
-- the job and never changed or deleted (the trigger below; no role is granted UPDATE or DELETE).
-- job.drawing_id names it (NULL for hobbing jobs and class jobs); a runner cannot change it (the
-- runner's column grants on job stay params, module_params, cutting). The proof takes those facts
-- from the record and `engine instantiate --job` refuses a job whose params disagree with it.
CREATE OR REPLACE FUNCTION refuse_changing_a_record() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (%)', TG_OP, TG_TABLE_NAME,
                    CASE TG_TABLE_NAME
                        WHEN 'program' THEN 'make a new program with engine instantiate'
                        WHEN 'template_audit' THEN 'the audit trail is append-only'
                        WHEN 'drawing' THEN 'import the drawing again with engine import-dxf'
                        ELSE 'a new version is stored when a template changes' END
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE TABLE drawing (
    id                 bigserial PRIMARY KEY,
    file_name          text NOT NULL,
    sha256             text CHECK (sha256 ~ '^[0-9a-f]{64}$'),   -- of the file's bytes; NULL: not known
    units              text,
    profile            jsonb NOT NULL CHECK (jsonb_typeof(profile) = 'array'),
    stock_diameter     double precision CHECK (stock_diameter > 0),   -- NULL: the blank is assumed
    stock_z_front      double precision,
    stock_z_back       double precision,
    tool_change_x      double precision,
    tool_change_z      double precision,
    workpiece_material text,
    tool_materials     jsonb CHECK (tool_materials IS NULL OR jsonb_typeof(tool_materials) = 'object'),
    imported_by        text NOT NULL DEFAULT current_user,
    imported_at        timestamptz NOT NULL DEFAULT now()
);
CREATE TRIGGER drawing_is_a_record BEFORE UPDATE OR DELETE ON drawing
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER drawing_is_not_truncated BEFORE TRUNCATE ON drawing
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

ALTER TABLE job ADD COLUMN drawing_id bigint REFERENCES drawing (id);

-- One record per job made from a drawing before this migration, from its params as they are now
-- (the file's bytes are not known: sha256 NULL), said to be made by this migration.
INSERT INTO drawing (id, file_name, units, profile, stock_diameter, stock_z_front, stock_z_back, tool_change_x,
                     tool_change_z, workpiece_material, tool_materials, imported_by, imported_at)
SELECT j.id, coalesce(j.params->>'drawing', 'job ' || j.id), j.params->>'units', j.params->'profile',
       (j.params->>'stock_diameter')::double precision, (j.params->>'stock_z_front')::double precision,
       (j.params->>'stock_z_back')::double precision, (j.params->>'tool_change_x')::double precision,
       (j.params->>'tool_change_z')::double precision, j.params->>'workpiece_material',
       (SELECT jsonb_object_agg(split_part(m.key, ':', 2), m.value->'tool_material')
        FROM jsonb_each(j.module_params) m
        WHERE m.key LIKE 'prep:%' AND jsonb_typeof(m.value) = 'object' AND m.value ? 'tool_material'),
       'migration 0027', j.created_at
FROM job j
WHERE j.params ? 'profile' AND jsonb_typeof(j.params->'profile') = 'array';
UPDATE job SET drawing_id = id WHERE id IN (SELECT id FROM drawing);
SELECT setval('drawing_id_seq', greatest((SELECT max(id) FROM drawing), 1), (SELECT max(id) FROM drawing) IS NOT NULL);

-- Runners import drawings (engine import-dxf): they insert records, never change them.
GRANT INSERT ON drawing TO engine_runner;
GRANT USAGE ON SEQUENCE drawing_id_seq TO engine_runner;
