-- Worm wheels (issue 14): the module a drawing states is the normal module m_n, or the axial
-- module m_x of the mating worm, which worm-gear drawings usually give (DIN 3975). The wheel's
-- normal module is m_n = m_x·cos γ (γ the worm's lead angle = the wheel's helix angle); read as a
-- normal module, an axial module 3 at γ = 4.05° cuts the wheel about 0.15 mm shallow. NULL = not
-- stated: cylindrical gears read it as normal, the worm-wheel model refuses it (no guess).
ALTER TABLE gear ADD COLUMN module_kind text CHECK (module_kind IN ('normal', 'axial'));
