-- Wheelbot: a small mobile robot (docs/module-types.md): a 0.20 x 0.12 x 0.05 m chassis (1.0 kg) on four
-- velocity-driven wheels (radius 0.04 m, 0.02 m wide, 0.05 kg; 10 rad/s, 0.5 N m), a forward
-- range sensor `range:front` (0.02 to 2.0 m, drawn as a ray) and genderless docks front and back
-- so it can tow or join other modules. Module frame: x forward, z up, origin at the chassis
-- centre, which rides 0.04 m above the ground on flat floor. The format is described in
-- superbot.lua.
-- Wheels at x = +-0.055: their rims reach 0.095 m, 5 mm behind the dock faces at 0.10 m, so two
-- Wheelbots meeting head on touch dock to dock and latch (at 0.07 the wheels stuck out 1 cm past
-- the docks and met first, 19 mm short of latching).
local kWheelX, kWheelY = 0.055, 0.075

local function wheel(name, x, y)
  return { name = name, mass = 0.05, color = { 0.1, 0.1, 0.1 }, friction = 1.2,
           shapes = { { cylinder = { 0.04, 0.02 }, axis = "y", at = { x, y, 0 } } } }
end

local function drive(name, x, y)
  return { name = name, parent = "chassis", child = name, pivot = { x, y, 0 }, axis = { 0, 1, 0 },
           continuous = true, torque = 0.5, speed = 10, gain = 20 }
end

return {
  name = "wheelbot",
  root = "chassis",
  links = {
    { name = "chassis", mass = 1.0, color = { 0.2, 0.6, 0.3 }, friction = 0.5,
      shapes = { { box = { 0.20, 0.12, 0.05 } } } },
    wheel("wheel_fl", kWheelX, kWheelY),
    wheel("wheel_fr", kWheelX, -kWheelY),
    wheel("wheel_rl", -kWheelX, kWheelY),
    wheel("wheel_rr", -kWheelX, -kWheelY),
  },
  joints = {
    drive("wheel_fl", kWheelX, kWheelY),
    drive("wheel_fr", kWheelX, -kWheelY),
    drive("wheel_rl", -kWheelX, kWheelY),
    drive("wheel_rr", -kWheelX, -kWheelY),
  },
  docks = {
    { name = "front", link = "chassis", at = { 0.10, 0, 0 }, normal = { 1, 0, 0 }, up = { 0, 0, 1 } },
    { name = "back", link = "chassis", at = { -0.10, 0, 0 }, normal = { -1, 0, 0 }, up = { 0, 0, 1 } },
  },
  sensors = {
    { type = "range", name = "front", link = "chassis", at = { 0.10, 0, 0 }, dir = { 1, 0, 0 }, min = 0.02, max = 2.0 },
    { type = "accelerometer", link = "chassis" },
    { type = "gyro", link = "chassis" },
    { type = "orientation" },
    { type = "position" },
    { type = "contact", link = "chassis" },
  },
}
