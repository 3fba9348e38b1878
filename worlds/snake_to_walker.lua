-- Self-reconfiguration on the ground: eight SuperBots lying as a snake turn themselves into a
-- legged walker (a head, a 3-module body and four one-module legs on the body's side docks).
-- Every module runs behaviors/reconfigure.lua and knows only the target shape: the modules learn
-- their shape from dock messages, agree on one map, each computes the same plan
-- (lua/reconfig.lua) and the same steps (lua/lay_retrieve.lua: lay the tail's modules beside the
-- chain, crawl backwards until the side docks capture them), and carry the steps out by messages.
-- This script only observes: it prints the plan and the steps, every dock event as it happens,
-- and at the end the time, the peak dock load and the messages a module sent.
--
-- Checks (once the run has lasted its 75 s): every module finished, the world's connection graph
-- is the target's, no connection broke, and no dock carried more than 60% of its strength (100 N,
-- 10 N m).
-- Try: --param modules=12 (a longer body; the legs stay four).
local reconfig = require("reconfig")
local n = args.modules or 8
if type(n) ~= "number" or n < 8 or n % 2 ~= 0 then
  error("--param modules: an even number, at least 8, got " .. tostring(args.modules))
end
local duration = 75 + (n - 8) * 10
world.set{dt = 1 / 60, duration = duration}
world.ground{friction = 0.8}

-- The target: a chain of n - 4 modules (its head, then the body) with a left and a right leg on
-- the second and the last chain module.
local roles, conns = {}, {}
local chain = n - 4
for i = 1, chain do roles["c" .. i] = "superbot" end
for i = 1, chain - 1 do conns[#conns + 1] = {"c" .. i, "back", "c" .. (i + 1), "front"} end
for k, body in ipairs({2, chain}) do
  roles["leg" .. (2 * k - 1)], roles["leg" .. (2 * k)] = "superbot", "superbot"
  conns[#conns + 1] = {"c" .. body, "left", "leg" .. (2 * k - 1), "front"}
  conns[#conns + 1] = {"c" .. body, "right", "leg" .. (2 * k), "front"}
end
local target = {modules = roles, connections = conns}

local mods = {}
for i = 1, n do
  mods[i] = world.spawn("superbot", {name = "s" .. i, at = i == 1 and {0, 0, 0.05} or nil,
                                     behavior = "behaviors/reconfigure.lua", params = {target = target}})
  if i > 1 then world.connect(mods[i - 1], "back", mods[i], "front") end
end
world.camera{eye = {-1.0, -0.8, 0.6}, target = {-1.5, 0.05, 0}}

local names = {}
for _, m in ipairs(mods) do names[m.id] = m.name end
local shown, seen, peak, peakAt, finished = false, nil, {force = 0, torque = 0}, nil, nil
local docks = world.module_type("superbot").docks
world.every(1 / 60, function(t)
  if not shown and mods[1]:published("steps") then
    shown = true
    print("plan:\n" .. mods[1]:published("plan"))
    print("steps:\n" .. mods[1]:published("steps"))
  end
  local events = world.events()
  for i = (seen or #events) + 1, #events do  -- (the snake's own connections, made before the first step, are not news)
    local e = events[i]
    print(string.format("%s %s.%s - %s.%s", e.event, names[e.module_a], e.dock_a, names[e.module_b], e.dock_b))
  end
  seen = #events
  for _, m in ipairs(mods) do
    for _, d in ipairs(docks) do
      local l = m:dock_load(d.name)
      if l and (l.force > peak.force or l.torque > peak.torque) then
        peak = {force = math.max(peak.force, l.force), torque = math.max(peak.torque, l.torque)}
        peakAt = t
      end
    end
  end
  if not finished then
    local all = true
    for _, m in ipairs(mods) do
      if not m:published("reconfigured") then all = false end
      local why = m:published("failed") or m:published("error")
      if why then
        print(m.name .. ": " .. why)
        world.stop()
        return
      end
    end
    if all then
      finished = t
      print(string.format("t=%.1f s  the walker is built", t))
    end
  end
end)

world.on_end(function(t)
  local sent = 0
  for _, m in ipairs(mods) do sent = sent + (m:published("messages") or 0) end
  local broken = 0
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken = broken + 1 end
  end
  print(string.format("peak dock load %.1f N, %.2f N m (at %.1f s); %.1f messages a module", peak.force, peak.torque,
                      peakAt or 0, sent / n))
  world.metric("reconfigured_s", finished or -1)
  world.metric("peak_force_n", peak.force)
  world.metric("messages_per_module", sent / n)
  if t < duration - 1e-9 and not finished then return end  -- a shortened run checks nothing
  expect(finished ~= nil, "every module finished its steps")
  local left = reconfig.plan(reconfig.from_world(world), reconfig.shape(target))
  expect(#left.ops == 0, "the world's graph is the walker's: " .. #left.ops .. " operations from it")
  expect(broken == 0, broken .. " connections broke")
  expect(peak.force < 60 and peak.torque < 6, string.format("dock loads within 60%% of the docks' strength: %.1f N, %.2f N m",
                                                            peak.force, peak.torque))
end)
