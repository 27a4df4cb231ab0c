-- Issue 29: the floor-to-floor time a planner needs, beside the cutting time. The machine record
-- states the times of what a hobbing program does besides cutting (seconds unless said): the
-- swivel head's speed (degrees per second), the hob spindle's run-up at each start (M3/M4), the
-- table's synchronisation at each coupling (EGON), the tailstock's clamp and its release (M20 and
-- M21, each), the door's close and its open (each), a tool call (T), and loading and unloading one
-- part. NULL: not stated; a program for a machine that does not state them all says no
-- floor-to-floor time (engine.hobbing.floor_time; the simulation holds a stated one to the program
-- text, engine.simulation.hobbing.floor_facts). Existing records are left as the shop wrote them.
ALTER TABLE machine
    ADD COLUMN swivel_speed numeric CHECK (swivel_speed > 0),
    ADD COLUMN spindle_runup numeric CHECK (spindle_runup >= 0),
    ADD COLUMN coupling_sync numeric CHECK (coupling_sync >= 0),
    ADD COLUMN tailstock_time numeric CHECK (tailstock_time >= 0),
    ADD COLUMN door_time numeric CHECK (door_time >= 0),
    ADD COLUMN tool_change_time numeric CHECK (tool_change_time >= 0),
    ADD COLUMN load_unload_time numeric CHECK (load_unload_time >= 0);
