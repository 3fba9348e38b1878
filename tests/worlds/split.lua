-- Undocking: in a 3-module chain the middle module disables its back dock at t = 1 s; the
-- connection goes in that step, the chain splits into two components, and both keep moving.
world.set{duration = 2}
world.ground{}
local m = {}
for i = 1, 3 do
  m[i] = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "../behaviors/splitter.lua",
                                  params = {split_at = i == 2 and 1.0 or nil}})
  if i > 1 then world.connect(m[i - 1], "back", m[i], "front") end
end
world.at(0.9, function()
  expect(#world.components() == 1, "one chain before the split")
end)
world.at(1.1, function()
  local comps = world.components()
  expect(#comps == 2, "two components after the split, got " .. #comps)
  expect(not m[2]:dock_state("back").engaged and not m[3]:dock_state("front").engaged, "the docks let go")
  expect(m[1]:dock_state("back").engaged, "the other connection holds")
  expect(world.graph("dot"):find("m1 -- m2", 1, true) and not world.graph("dot"):find("m2 -- m3", 1, true),
         "the DOT graph shows the split")
end)
local a0, b0
world.at(1.25, function() a0, b0 = m[1]:joint_angle("pitch"), m[3]:joint_angle("pitch") end)
world.at(1.5, function()
  expect(math.abs(m[1]:joint_angle("pitch") - a0) > 0.2 and math.abs(m[3]:joint_angle("pitch") - b0) > 0.2,
         "both parts keep moving")
end)
