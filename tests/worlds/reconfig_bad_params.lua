-- behaviors/reconfigure.lua refuses bad params when it loads: the module faults alone, with a
-- message naming the behaviour's line and the parameter, and the rest of the world runs on.
world.set{duration = 0.1, expect_faults = 9}  -- one a case
world.ground{}
local shape = {modules = {"a", "b"}, connections = {{"a", "back", "b", "front"}}}
local cases = {
  {{target = shape, quiet = "soon"}, "params.quiet: expected steps (a whole number, at least 1), got soon"},
  {{target = 5}, "params.target: expected a shape"},
  {{targets = {shape, "snake"}}, "params.targets[2]: expected a shape, got string"},
  {{target = shape, walk = -1}, "params.walk: expected metres (a number, at least 0), got -1"},
  {{target = shape, noise = {joints = "a lot"}}, "params.noise.joints: expected a standard deviation"},
  {{target = shape, noise = {joint_offset = -0.1}}, "params.noise.joint_offset: expected a standard deviation"},
  {{target = shape, noise = {joint_wander = 0.01, joint_wander_tau = 0}},
   "params.noise.joint_wander_tau: expected seconds (a number, more than 0), got 0"},
  {{target = shape, leave_at = "later"}, "params.leave_at: expected seconds (a number), got later"},
  {{target = {modules = {"a"}, connections = {{"a", "back", "c", "front"}}}}, "connections[1]: unknown module 'c'"},
}
local mods = {}
for i, c in ipairs(cases) do
  mods[i] = world.spawn("superbot", {name = "m" .. i, at = {0, i, 0.05}, behavior = "behaviors/reconfigure.lua",
                                     params = c[1]})
end
local fine = world.spawn("superbot", {name = "fine", at = {1, 0, 0.05}})
-- Good params load: noise = true (every default) and a table of some kinds.
local good = {
  world.spawn("superbot", {name = "g1", at = {2, 0, 0.05}, behavior = "behaviors/reconfigure.lua",
                           params = {target = shape, noise = true}}),
  world.spawn("superbot", {name = "g2", at = {2, 1, 0.05}, behavior = "behaviors/reconfigure.lua",
                           params = {target = shape, noise = {joint_offset = 0.01, joint_wander = 0.01}}}),
}
world.on_end(function()
  for i, c in ipairs(cases) do
    local e = mods[i]:error() or ""
    expect(e:find("behaviors/reconfigure.lua:%d+:") ~= nil and e:find(c[2], 1, true) ~= nil,
           "case " .. i .. " refused with '" .. c[2] .. "': " .. e)
  end
  expect(fine:error() == nil, "the other module runs on")
  for _, g in ipairs(good) do expect(g:error() == nil, g.name .. " loads: " .. tostring(g:error())) end
end)
