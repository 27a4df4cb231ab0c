-- Lint for imported classes: a class brought in from a proven NC program has no hobbing
-- model, so the names its template may use are the parameters it was imported with.

-- The parameter values of the proven program the class was imported from (engine
-- import-nc); lint checks the template's names against them. NULL: not imported.
ALTER TABLE gear_class ADD COLUMN import_params jsonb
    CHECK (jsonb_typeof(import_params) = 'object');
