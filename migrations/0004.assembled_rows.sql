-- Every class's assembled rows in one set-based statement. class_template(name) suits one
-- class; called per class (template_view, the nightly refactor) the planner may scan
-- component once per class, which grows with classes x components.

-- (gear_class, id, n, component_id, owner): a class's own rows and those it inherits, the
-- nearest ancestor winning by row id, exactly as class_template(gear_class) gives them.
CREATE VIEW assembled_row AS
WITH RECURSIVE lineage(gear_class, ancestor, depth) AS (
    SELECT g.name, g.name, 0 FROM gear_class g
    UNION ALL
    SELECT l.gear_class, g.parent, l.depth + 1
    FROM lineage l JOIN gear_class g ON g.name = l.ancestor
    WHERE g.parent IS NOT NULL AND l.depth < 50)
SELECT DISTINCT ON (l.gear_class, a.id) l.gear_class, a.id, a.n, a.component_id, a.gear_class AS owner
FROM lineage l JOIN assembly a ON a.gear_class = l.ancestor
ORDER BY l.gear_class, a.id, l.depth;

CREATE OR REPLACE VIEW template_view AS
WITH body_use AS (
    SELECT component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit) AS body,
           count(DISTINCT a.gear_class)::integer AS classes
    FROM assembled_row a JOIN component c ON c.id = a.component_id
    GROUP BY 1)
SELECT a.gear_class, a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit, u.classes AS shared_by,
       a.owner AS inherited_from
FROM assembled_row a
JOIN component c ON c.id = a.component_id
JOIN body_use u ON u.body = component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit);
