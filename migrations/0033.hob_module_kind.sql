-- Issue 29: worm-wheel hobs are catalogued by the worm's axial module m_x (DIN 3975), and the
-- engine matched every hob's module to the wheel's normal module: every catalogue hob was refused,
-- and one entered as normal coupled the tangential feed with the wrong pitch (2 % at γ 11.6°).
-- A hob now says which module its record gives; the engine converts it once, on load
-- (engine.gears.hob_geometry.normal_from_axial). Hobs stored before keep what the engine read
-- them as: normal. Only a worm-wheel hob copies a worm, so only it may be axial.
ALTER TABLE hob
    ADD COLUMN module_kind text NOT NULL DEFAULT 'normal' CHECK (module_kind IN ('normal', 'axial')),
    ADD CONSTRAINT hob_axial_module_of_worm_wheel_hobs CHECK (module_kind = 'normal' OR purpose = 'worm_wheel');
