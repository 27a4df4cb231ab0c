-- Template versions (issue 6): the assembled template of every committed version of every
-- class, so `engine template history`, `diff` and `restore` can show and bring back any of
-- them. Append-only: a version's rows are written once, when the transaction that made the
-- version commits, and never changed.

-- rows: the assembled template (own and inherited rows) as a JSON array in id order of
-- {"id", "t", "n", "p_calc", "s", "o", "p_emit"} (template_row_json).
CREATE TABLE template_version_rows (
    gear_class text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    version    integer NOT NULL,
    rows       jsonb NOT NULL,
    created_at timestamptz NOT NULL DEFAULT now(),
    created_by text NOT NULL DEFAULT current_user,
    PRIMARY KEY (gear_class, version)
);

-- The class's assembled rows as template_version_rows stores them.
CREATE FUNCTION class_rows_array(class_name text)
RETURNS jsonb LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_agg(template_row_json(r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit) ORDER BY r.id),
                        '[]')
        FROM class_template(class_name) r JOIN component c ON c.id = r.component_id);

-- At commit, once per changed class: store the class's version as committed (its version and
-- rows read then, so several bumps in one transaction store the one state others can see).
-- SECURITY DEFINER: editors need no rights on template_version_rows.
CREATE FUNCTION store_template_version() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    INSERT INTO template_version_rows (gear_class, version, rows, created_by)
    SELECT g.name, g.template_version, class_rows_array(g.name), template_editor()
    FROM gear_class g WHERE g.name = NEW.name
    ON CONFLICT (gear_class, version) DO NOTHING;
    RETURN NULL;
END
$$;

CREATE CONSTRAINT TRIGGER store_template_version
AFTER INSERT OR UPDATE OF template_version ON gear_class
DEFERRABLE INITIALLY DEFERRED
FOR EACH ROW EXECUTE FUNCTION store_template_version();

-- Every class's current version, for databases migrated after their templates were loaded.
INSERT INTO template_version_rows (gear_class, version, rows, created_by)
SELECT g.name, g.template_version, class_rows_array(g.name), current_user
FROM gear_class g
ON CONFLICT (gear_class, version) DO NOTHING;

GRANT SELECT ON template_version_rows TO engine_reader, engine_runner, engine_editor;
