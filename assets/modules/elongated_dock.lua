-- Elongated dock: a passive rigid bar, 0.1 m dock face to dock face, 0.06 m square, 0.1 kg, with a
-- genderless SuperBot-compatible dock at each end (`front` at +x, `back` at -x). It lengthens an
-- arm or a chain (the paper's 9-DOF arm joins three SuperBots with two of these). No joints, so a
-- behaviour on it can only sense, relay messages and switch its docks.
-- Other sizes: lua/elongated_dock_type.lua makes one from {length=, width=, mass=, ...}; a
-- one-line type file gives it a name (see that file).
return require("elongated_dock_type").make{}
