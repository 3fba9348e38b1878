-- The elongated dock as a function of its size: a passive rigid bar (no joints) with a genderless,
-- SuperBot-compatible dock at each end. assets/modules/elongated_dock.lua is the default (0.1 m);
-- a module-type file makes another length in one line (a type file may require this from
-- assets/modules/ or lua/), e.g. assets/modules/elongated_dock_long.lua:
--
--   return require("elongated_dock_type").make{ name = "elongated_dock_long", length = 0.2 }
--
-- make{...} fields (all optional; SI units):
--   name      type name                                   default "elongated_dock"
--   length    dock face to dock face, m (0.01 .. 2)        default 0.1
--   width     square section of the bar, m                default 0.06
--   mass      kg                                          default 1.0 kg/m * length
--   strength, strength_torque   the docks' breaking force (N) and torque (N m): default 100, 10
--   color     {r, g, b}
-- The module frame is the bar's centre, x along the bar: dock `front` at x = +length/2 (normal +x),
-- `back` at x = -length/2 (normal -x), both with `up` = +z, like a SuperBot's front and back.
local M = {}

local kKnown = { name = true, length = true, width = true, mass = true, strength = true,
                 strength_torque = true, color = true }

local function number(opts, key, default, lo, hi)
  local v = opts[key]
  if v == nil then return default end
  if type(v) ~= "number" or v ~= v or v < lo or v > hi then
    error(string.format("elongated_dock: %s must be a number in [%g, %g], got %s", key, lo, hi,
                        tostring(v)), 3)
  end
  return v
end

function M.make(opts)
  opts = opts or {}
  for k in pairs(opts) do
    if not kKnown[k] then
      error("elongated_dock: unknown field '" .. tostring(k) ..
            "' (expected name, length, width, mass, strength, strength_torque, color)", 2)
    end
  end
  local length = number(opts, "length", 0.1, 0.01, 2)
  local width = number(opts, "width", 0.06, 0.01, 0.5)
  local mass = number(opts, "mass", 1.0 * length, 1e-3, 100)
  local strength = number(opts, "strength", 100, 0, 1e6)
  local strengthTorque = number(opts, "strength_torque", 10, 0, 1e6)
  local function dock(name, sign)
    return { name = name, link = "bar", at = { sign * length / 2, 0, 0 }, normal = { sign, 0, 0 },
             up = { 0, 0, 1 }, gender = "none", size = 0.034, symmetry = 4,
             strength = strength, strength_torque = strengthTorque }
  end
  return {
    name = opts.name or "elongated_dock",
    links = {
      { name = "bar", mass = mass, color = opts.color or { 0.55, 0.6, 0.7 }, friction = 1.0,
        shapes = { { box = { length, width, width } } } },
    },
    docks = { dock("front", 1), dock("back", -1) },
    sensors = {
      { type = "accelerometer" }, { type = "orientation" }, { type = "position" },
      { type = "contact", link = "bar" },
    },
  }
end

return M
