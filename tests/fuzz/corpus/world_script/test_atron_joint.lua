-- The ATRON equator is a continuous joint: no limits, and its angle is unwrapped.
-- * spinner: set_velocity(1) for 8 s. The angle grows all the time (every half-second sample
--   larger than the last), passes 2 pi, and is over 6 rad after 7 s; the motor's speed limit
--   (1 rad/s) keeps it under 7.1 rad.
-- * servo: set_target(3.5), beyond pi, from 0. At 1 rad/s it needs 3.5 s; after 5 s the angle is
--   3.5 rad within 2 degrees (a wrapped angle would read -2.78 rad there).
-- Both modules rest on the ground on their south pole, axis vertical.
world.set{duration = 8}
world.ground{friction = 0.8}
local spinner = world.spawn("atron", {at = {0, 0, 0.057}, name = "spinner", behavior = "behaviors/hold.lua",
                                      params = {velocities = {equator = 1}}})
local servo = world.spawn("atron", {at = {0.5, 0, 0.057}, name = "servo", behavior = "behaviors/hold.lua",
                                    params = {targets = {equator = 3.5}}})

local last = spinner:joint_angle("equator")
local samples = 0
world.every(0.5, function(t)
  local a = spinner:joint_angle("equator")
  expect(a > last + 0.3, string.format("t=%.1f: the spinner's angle grows, %.3f after %.3f rad", t, a, last))
  last = a
  samples = samples + 1
end)

world.at(7, function()
  local a = spinner:joint_angle("equator")
  log(string.format("spinner at %.3f rad after 7 s", a))
  expect(a > 6 and a > 2 * math.pi, string.format("the spinner turned past 2 pi: %.3f rad after 7 s, expected > 6", a))
  expect(a < 7.1, string.format("the spinner kept to 1 rad/s: %.3f rad after 7 s", a))
end)

world.at(5, function()
  local a = servo:joint_angle("equator")
  log(string.format("servo at %.4f rad after 5 s", a))
  expect(math.abs(math.deg(a - 3.5)) < 2, string.format("servo reached 3.5 rad within 2 deg: %.4f rad", a))
end)

world.at(8, function()
  expect(samples >= 15, "the spinner was sampled every 0.5 s, " .. samples .. " samples")
  for _, m in ipairs({spinner, servo}) do
    expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error()))
  end
  local a = servo:joint_angle("equator")
  expect(math.abs(math.deg(a - 3.5)) < 2, string.format("servo holds 3.5 rad: %.4f rad after 8 s", a))
end)
