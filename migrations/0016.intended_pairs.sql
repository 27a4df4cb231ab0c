-- Near-duplicate pairs of the nightly refactor (issue 16): what earlier runs reported, so a run
-- lists the pairs it finds for the first time before the ones a person has already seen; and the
-- pairs a person marked intended (who, why, when), which the report no longer lists, only counts.
--
-- A pair is its module type and its two line texts, in either order (engine.library.intended);
-- pair_key is the engine's sha256 of that identity, the report shows its first 12 hex digits. The
-- texts are kept beside it so that whoever reads these tables in SQL sees the pair itself.

-- One row per pair a refactor run has listed: first_seen decides new (this run) or known.
CREATE TABLE near_duplicate_seen (
    pair_key   text PRIMARY KEY CHECK (pair_key ~ '^[0-9a-f]{64}$'),
    t          text NOT NULL,
    a          text NOT NULL,
    b          text NOT NULL,
    first_seen timestamptz NOT NULL DEFAULT now(),
    last_seen  timestamptz NOT NULL DEFAULT now()
);

-- A pair marked intended: kept on purpose (e.g. the spur and the helical coupling differ by the
-- helical differential). Withdrawing a mark keeps its row (who withdrew it, when): the decision
-- and its reversal stay readable; a pair has at most one mark in force.
CREATE TABLE near_duplicate_intended (
    id             bigserial PRIMARY KEY,
    pair_key       text NOT NULL CHECK (pair_key ~ '^[0-9a-f]{64}$'),
    t              text NOT NULL,
    a              text NOT NULL,
    b              text NOT NULL,
    why            text NOT NULL CHECK (btrim(why) <> ''),
    marked_at      timestamptz NOT NULL DEFAULT now(),
    marked_by      text NOT NULL DEFAULT session_user,       -- the login person
    marked_role    text NOT NULL DEFAULT template_editor(),  -- the role acting (SET ROLE)
    withdrawn_at   timestamptz,
    withdrawn_by   text,
    withdrawn_role text
);
CREATE UNIQUE INDEX near_duplicate_intended_in_force ON near_duplicate_intended (pair_key)
    WHERE withdrawn_at IS NULL;

-- Who and when are stamped by the database, not taken from the client; a mark is withdrawn once.
CREATE FUNCTION stamp_near_duplicate_intent() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    IF TG_OP = 'INSERT' THEN
        NEW.marked_at := now();
        NEW.marked_by := session_user;
        NEW.marked_role := template_editor();
        NEW.withdrawn_at := NULL;
        NEW.withdrawn_by := NULL;
        NEW.withdrawn_role := NULL;
        RETURN NEW;
    END IF;
    IF OLD.withdrawn_at IS NOT NULL THEN
        RAISE EXCEPTION 'near-duplicate mark % was withdrawn already', OLD.id USING ERRCODE = 'check_violation';
    END IF;
    NEW := OLD;
    NEW.withdrawn_at := now();
    NEW.withdrawn_by := session_user;
    NEW.withdrawn_role := template_editor();
    RETURN NEW;
END
$$;

CREATE TRIGGER near_duplicate_intended_stamped BEFORE INSERT OR UPDATE ON near_duplicate_intended
FOR EACH ROW EXECUTE FUNCTION stamp_near_duplicate_intent();

-- Everybody reads both. Editors (who unify near-duplicates by hand) mark and withdraw; the
-- nightly run writes what it reported: engine_runner, the role of unattended jobs (the refactor
-- itself also rewrites the library, which needs its owner).
GRANT SELECT ON near_duplicate_seen, near_duplicate_intended
    TO engine_reader, engine_runner, engine_editor, engine_releaser;
GRANT INSERT (pair_key, t, a, b, why), UPDATE (withdrawn_at) ON near_duplicate_intended TO engine_editor;
GRANT USAGE ON SEQUENCE near_duplicate_intended_id_seq TO engine_editor;
GRANT INSERT, UPDATE (last_seen) ON near_duplicate_seen TO engine_runner;
