-- Issue 26 (finding 7): a release record says only what is true. release_template stores what its
-- caller states (the tests it ran, the impact): a releaser calling it by hand from SQL could store
-- invented results for a draft the gate refused, and `template history` showed them as the gate's.
-- The database cannot run the gate, so the record now keeps (1) how the release was made,
-- released_via: 'engine' (engine template release, after its gate), 'seed' (engine seed: the
-- shipped templates), 'sql' (by hand: the default of the raw call), 'unrecorded' (before this
-- migration); the caller names it, so it says what the releasing login claims, never a proof; and
-- (2) golden_tests, the golden tests of the class and its descendants as the database holds them at
-- the release, each with its class's version then: the database takes them from template_test, not
-- from the caller. Every screen that shows a release re-runs those tests and the lint and analysis
-- of the released version (engine.release.recheck) and says "gate passed" only for an engine
-- release whose re-check passes (docs/design.md §10, threat model).
ALTER TABLE template_release ADD COLUMN released_via text NOT NULL DEFAULT 'unrecorded'
    CHECK (released_via IN ('engine', 'seed', 'sql', 'unrecorded'));
ALTER TABLE template_release ALTER COLUMN released_via SET DEFAULT 'sql';
ALTER TABLE template_release ADD COLUMN golden_tests jsonb
    CHECK (golden_tests IS NULL OR jsonb_typeof(golden_tests) = 'array');

DROP FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text);

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

REVOKE EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) TO engine_releaser;
