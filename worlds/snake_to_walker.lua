-- Self-reconfiguration on the ground: eight SuperBots lying as a snake turn themselves into a
-- legged walker (a head, a 3-module body and four one-module legs on the body's side docks), and
-- it walks.
-- Every module runs behaviors/reconfigure.lua and knows only the target shape: the modules learn
-- their shape from dock messages, agree on one map, each computes the same plan
-- (lua/reconfig.lua) and the same steps (lua/lay_retrieve.lua: lay the tail's modules beside the
-- chain, crawl backwards until the side docks capture them), and carry the steps out by messages.
-- This script only observes: it prints the plan and the steps, every dock event as it happens,
-- and at the end the time, the peak dock load and the messages a module sent.
--
-- Once built, the walker trots 0.5 m forward (lua/walker_gait.lua).
--
-- Checks (once the run has lasted its 100 s, 70 + 60 per metre walked): every module finished, the walker walked 0.5 m, the
-- world's connection graph is the target's, no connection broke, and no dock carried more than
-- 70% of its strength (100 N, 10 N m).
-- Try: --param modules=12 (a six-legged walker), --param walk=1 (metres).
local reconfig = require("reconfig")
local n = args.modules or 8
if type(n) ~= "number" or n < 8 or n % 4 ~= 0 then
  error("--param modules: a multiple of 4, at least 8, got " .. tostring(args.modules))
end
local walk = args.walk or 0.5
if type(walk) ~= "number" or walk < 0 then
  error("--param walk: metres, at least 0, got " .. tostring(args.walk))
end
local duration = 70 + 60 * walk + (n - 8) * 10
world.set{dt = 1 / 60, duration = duration}
world.ground{friction = 0.8}

-- The target: a chain of n/2 modules (its head, then the body) with a left and a right leg on every
-- second chain module (8 modules: four legs on the second and the fourth; 12: six legs).
local roles, conns = {}, {}
local chain = n // 2
for i = 1, chain do roles["c" .. i] = "superbot" end
for i = 1, chain - 1 do conns[#conns + 1] = {"c" .. i, "back", "c" .. (i + 1), "front"} end
for k = 1, chain // 2 do
  local body = 2 * k
  roles["leg" .. (2 * k - 1)], roles["leg" .. (2 * k)] = "superbot", "superbot"
  conns[#conns + 1] = {"c" .. body, "left", "leg" .. (2 * k - 1), "front"}
  conns[#conns + 1] = {"c" .. body, "right", "leg" .. (2 * k), "front"}
end
local target = {modules = roles, connections = conns}

local mods = {}
for i = 1, n do
  mods[i] = world.spawn("superbot", {name = "s" .. i, at = i == 1 and {0, 0, 0.05} or nil,
                                     behavior = "behaviors/reconfigure.lua",
                                     params = {target = target, walk = walk}})
  if i > 1 then world.connect(mods[i - 1], "back", mods[i], "front") end
end
world.camera{eye = {-0.7, -0.85, 0.6}, target = {-1.25, -0.05, 0}}

local names = {}
for _, m in ipairs(mods) do names[m.id] = m.name end
local shown, seen, peak, peakAt, finished, failed = false, nil, {force = 0, torque = 0}, nil, nil, nil
local walked
local built, builtAt  -- when the world's graph became the walker's, and where the head was then
local goal = reconfig.shape(target)
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
  if not built and #events > 0 and events[#events].event == "engaged" and
      #reconfig.plan(reconfig.from_world(world), goal).ops == 0 then
    built, builtAt = t, mods[1]:position()
    print(string.format("t=%.1f s  the walker is built", t))
  end
  if not finished then
    local all = true
    for _, m in ipairs(mods) do
      if not m:published("reconfigured") then all = false end
      local why = m:published("failed") or m:published("error")
      if why then
        failed = m.name .. ": " .. why
        print(failed)
        world.stop()
        return
      end
    end
    if all then
      finished = t
      local p = mods[1]:position()
      walked = built and math.sqrt((p.x - builtAt.x) ^ 2 + (p.y - builtAt.y) ^ 2) or 0
      print(string.format("t=%.1f s  done: the head moved %.3f m since the walker was built", t, walked))
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
  world.metric("built_s", built or -1)
  world.metric("walked_m", walked or 0)
  world.metric("peak_force_n", peak.force)
  world.metric("messages_per_module", sent / n)
  expect(failed == nil, "no step failed: " .. tostring(failed))
  if t < duration - 1e-9 and not finished then return end  -- a shortened run checks nothing else
  expect(finished ~= nil, "every module finished its steps")
  expect((walked or 0) >= walk, string.format("the walker walked %.2f m: %.3f m", walk, walked or 0))
  local left = reconfig.plan(reconfig.from_world(world), goal)
  expect(#left.ops == 0, "the world's graph is the walker's: " .. #left.ops .. " operations from it")
  expect(broken == 0, broken .. " connections broke")
  expect(peak.force < 70 and peak.torque < 7, string.format("dock loads within 70%% of the docks' strength: %.1f N, %.2f N m",
                                                            peak.force, peak.torque))
end)
