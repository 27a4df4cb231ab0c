-- Issue 31: only the database owner could import gears, units, hobs, cases, work-holdings,
-- machines or materials (every engine role read them only). engine_planner is the role of the
-- person who keeps the shop's data (docs/design.md §10): it adds and replaces the library's
-- records, through the engine's imports or by hand, and deletes gears and hobs no job was made
-- from (the foreign keys of job refuse the others). It changes no template, release, program,
-- job or audit row; in the machining history it adds and replaces cases' values but never says
-- which job a case came from, nor when (the database's own record).

-- The role (NOLOGIN, cluster-wide: created once, whichever database migrates first).
DO $$
BEGIN
    IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'engine_planner') THEN
        BEGIN
            CREATE ROLE engine_planner NOLOGIN;
        EXCEPTION WHEN duplicate_object OR unique_violation THEN
            NULL;   -- created meanwhile by a migration of another database
        END;
    END IF;
END
$$;

-- It reads what the other roles read (not the per-transaction change markers).
GRANT USAGE ON SCHEMA public TO engine_planner;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_planner;
REVOKE ALL ON template_change, template_check_due FROM engine_planner;
GRANT SELECT ON SEQUENCE component_id_seq, cutting_case_id_seq, job_id_seq, program_id_seq, template_audit_id_seq
    TO engine_planner;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_planner;

-- The library: workpieces and their further units, hobs, work-holdings, machines, materials.
GRANT INSERT, UPDATE, DELETE ON gear, gear_unit, hob TO engine_planner;
GRANT INSERT, UPDATE ON work_holding, machine, material TO engine_planner;
-- The machining history: a case's values (an import's ids move the sequence past them), never
-- its job or its time.
GRANT INSERT (id, module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts,
              hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source),
      UPDATE (module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts,
              hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source)
    ON cutting_case TO engine_planner;
GRANT USAGE, UPDATE ON SEQUENCE cutting_case_id_seq TO engine_planner;
