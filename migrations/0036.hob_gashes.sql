-- Issue 29 ("quality as a constraint"): a multi-start hob's feed was lowered by √z0, a rule of our
-- own. The engine now bounds every cylindrical gear's axial feed by the chip thickness of
-- Hoffmeister's formula (docs/reference/hobbing.md §C1), which reads the hob's gashes (flutes):
-- i = gashes/starts cutting edges share a workpiece revolution's feed. A hob also says its tooth
-- profile: standard (the basic rack profile, DIN 3972), protuberance (a tip protuberance that
-- undercuts the root ahead of shaving or grinding) or topping (its root also cuts the gear's tip).
-- Hobs stored before get 12 gashes, the usual count of solid HSS catalogue hobs of m1–m4 to
-- DIN 3968 (catalogues list 12–16 for them; 12 is the end that gives the thicker chip, so the
-- bound errs towards the lower feed) [K], and the standard profile, what the engine read them as.
ALTER TABLE hob
    ADD COLUMN gashes integer NOT NULL DEFAULT 12 CHECK (gashes > 0),
    ADD COLUMN profile text NOT NULL DEFAULT 'standard' CHECK (profile IN ('standard', 'protuberance', 'topping'));
