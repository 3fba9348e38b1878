-- Cloth with the exact joint solver: a sheet falls over a posed SuperBot whose servos hold a bent
-- pitch joint; it comes to rest on the module, no node goes through the ground, and the joint
-- still holds its angle under the sheet's weight.
world.set{duration = 3, solver = "exact"}
world.ground{friction = 0.8}
local m = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/hold.lua",
                                   params = {targets = {pitch = 0.5}}})
local c = world.cloth{corners = {{-0.3, -0.3, 0.4}, {0.3, -0.3, 0.4}, {0.3, 0.3, 0.4}, {-0.3, 0.3, 0.4}},
                      resolution = {20, 20}, mass = 0.05}
world.at(3, function()
  local b = c:bounds()
  expect(b ~= nil, "no node is NaN")
  expect(b.min.z > -0.001, string.format("no node through the ground (z=%.4f m)", b.min.z))
  expect(b.max.z > 0.1 and b.max.z < 0.15,
         string.format("the sheet rests on the module (top z=%.3f m)", b.max.z))
  local v = c:velocity()
  expect(math.sqrt(v.x ^ 2 + v.y ^ 2 + v.z ^ 2) < 0.02, "and is at rest")
  expect(math.abs(m:joint_angle("pitch") - 0.5) < 0.03,
         string.format("the pitch servo holds 0.5 rad under it (%.3f)", m:joint_angle("pitch")))
end)
