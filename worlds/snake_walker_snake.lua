-- Self-reconfiguration on the ground: eight SuperBots lying as a snake turn themselves into a
-- legged walker (a head, a 3-module body and four one-module legs on the body's side docks), the
-- walker trots 0.5 m, and it turns back into a snake.
--
-- Every module runs behaviors/reconfigure.lua and knows only the two target shapes. For each,
-- the modules learn their shape from dock messages, agree on one map, each computes the same
-- plan (lua/reconfig.lua) and the same steps (lua/lay_retrieve.lua), and they carry the steps out
-- by messages. To the walker: lay the tail's modules beside the chain, crawl backwards until the
-- side docks capture them, then trot (lua/walker_gait.lua). Back to the snake: let the legs go,
-- and crawl forward until the tail, its back bracket turned towards a leg, captures it.
-- This script only observes: it prints the plans and the steps, every dock event as it happens,
-- when each shape is reached, and at the end the peak dock load and the messages a module sent.
--
-- Checks (once the run has lasted its 240 s): every module finished, the walker was built and
-- walked 0.5 m, the robot is a snake again, no connection broke, and no dock carried more than
-- 70% of its strength (100 N, 10 N m).
-- Try: --param noise=1 (noise on the proximity, heading and position sensors and on every joint
-- target; --seed N draws other noise), --param noise=sensors (the sensors only; add joint errors with
-- --param joint_offset=RAD, a calibration error per joint, or joint_wander=RAD, a tracking error
-- that wanders over 1 s), --param walk=1 (metres), --param back=0 (stay a walker), --param modules=12 --param back=0
-- (a six-legged walker; it does not get back to a snake yet: its 6-module chain crawls forward at
-- 0.35 cm/s carrying four legs, and the first take times out).
local reconfig = require("reconfig")
local n = args.modules or 8
if type(n) ~= "number" or n < 8 or n % 4 ~= 0 then
  error("--param modules: a multiple of 4, at least 8, got " .. tostring(args.modules))
end
local walk = args.walk or 0.5
if type(walk) ~= "number" or walk < 0 then
  error("--param walk: metres, at least 0, got " .. tostring(args.walk))
end
local back = args.back ~= 0
-- Noise (behaviors/reconfigure.lua's defaults): 1 on the sensors and the joint targets, "sensors"
-- on the sensors only.
local noisy = args.noise == 1 or args.noise == "sensors"
if args.noise ~= nil and not noisy and args.noise ~= 0 then
  error("--param noise: 1 (sensors and joints), sensors, or 0, got " .. tostring(args.noise))
end
local noise = args.noise == "sensors" and {proximity = 0.005, heading = 0.01, position = 0.005} or noisy
for _, k in ipairs({"joint_offset", "joint_wander"}) do
  if args[k] ~= nil then
    if type(args[k]) ~= "number" or args[k] < 0 then
      error("--param " .. k .. ": radians (a number, at least 0), got " .. tostring(args[k]))
    end
    if type(noise) ~= "table" then error("--param " .. k .. ": goes with --param noise=sensors") end
    noise[k] = args[k]
  end
end
local duration = 80 + 60 * walk + (back and 130 or 0) + (n - 8) * 20
world.set{dt = 1 / 60, duration = duration}
world.ground{friction = 0.8}

-- The walker: a chain of n/2 modules (its head, then the body) with a left and a right leg on
-- every second chain module (8 modules: four legs on the second and the fourth; 12: six legs).
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
local walker = {modules = roles, connections = conns}
-- The snake: any n modules in a line, front to back (the planner gives each module its place).
local snake = {modules = {}, connections = {}}
for i = 1, n do snake.modules["t" .. i] = "superbot" end
for i = 1, n - 1 do snake.connections[i] = {"t" .. i, "back", "t" .. (i + 1), "front"} end

local mods = {}
for i = 1, n do
  mods[i] = world.spawn("superbot", {name = "s" .. i, at = i == 1 and {0, 0, 0.05} or nil,
                                     behavior = "behaviors/reconfigure.lua",
                                     params = {targets = back and {walker, snake} or {walker}, walk = walk,
                                               noise = noise}})
  if i > 1 then world.connect(mods[i - 1], "back", mods[i], "front") end
end
world.camera{eye = {-0.7, -0.85, 0.6}, target = {-1.25, -0.05, 0}}

local names = {}
for _, m in ipairs(mods) do names[m.id] = m.name end
local walkerShape, snakeShape = reconfig.shape(walker), reconfig.shape(snake)
local stages = back and 2 or 1
local shown, seen, peak, peakAt = 0, nil, {force = 0, torque = 0}, nil
local built, builtAt, walked, snakeAgain, finished, failed
local docks = world.module_type("superbot").docks

local function allFinished(stage)
  for _, m in ipairs(mods) do
    if (m:published("finished") or 0) < stage then return false end
  end
  return true
end

world.every(1 / 60, function(t)
  -- The plan and the steps of each stage, once (every module has the same).
  local stage = mods[1]:published("stage") or 1
  if shown < stage and mods[1]:published("steps") and (stage == 1 or mods[1]:published("finished") == stage - 1) then
    shown = stage
    print(string.format("to the %s: plan\n%s", stage == 1 and "walker" or "snake", mods[1]:published("plan")))
    print("steps:\n" .. mods[1]:published("steps"))
  end
  local events = world.events()
  for i = (seen or #events) + 1, #events do  -- (the snake's own connections, made before the first step, are not news)
    local e = events[i]
    print(string.format("%s %s.%s - %s.%s", e.event, names[e.module_a], e.dock_a, names[e.module_b], e.dock_b))
  end
  local changed = seen and #events > seen
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
  if changed and not built and #reconfig.plan(reconfig.from_world(world), walkerShape).ops == 0 then
    built, builtAt = t, mods[1]:position()
    print(string.format("t=%.1f s  the walker is built", t))
  end
  if built and not walked and allFinished(1) then
    local p = mods[1]:position()
    walked = math.sqrt((p.x - builtAt.x) ^ 2 + (p.y - builtAt.y) ^ 2)
    print(string.format("t=%.1f s  the walker has walked: the head moved %.3f m", t, walked))
  end
  if back and changed and walked and not snakeAgain and #reconfig.plan(reconfig.from_world(world), snakeShape).ops == 0 then
    snakeAgain = t
    print(string.format("t=%.1f s  a snake again", t))
  end
  if not finished and allFinished(stages) then finished = t end
  if not failed then
    for _, m in ipairs(mods) do
      local why = m:published("failed") or m:published("error")
      if why then
        failed = m.name .. ": " .. why
        print(failed)
        world.stop()
        return
      end
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
  world.metric("walker_built_s", built or -1)
  world.metric("walked_m", walked or 0)
  world.metric("snake_again_s", snakeAgain or -1)
  world.metric("peak_force_n", peak.force)
  world.metric("messages_per_module", sent / n)
  expect(failed == nil, "no step failed: " .. tostring(failed))
  if t < duration - 1e-9 and not finished then return end  -- a shortened run checks nothing else
  expect(finished ~= nil, "every module finished its steps")
  expect(built ~= nil, "the walker was built")
  -- (The head stops at `walk` by its own position sensor, which is noisy with --param noise=1.)
  expect((walked or 0) >= walk - (noisy and 0.02 or 0), string.format("the walker walked %.2f m: %.3f m", walk, walked or 0))
  if back then
    expect(snakeAgain ~= nil and #reconfig.plan(reconfig.from_world(world), snakeShape).ops == 0, "a snake again")
  end
  expect(broken == 0, broken .. " connections broke")
  expect(peak.force < 70 and peak.torque < 7, string.format("dock loads within 70%% of the docks' strength: %.1f N, %.2f N m",
                                                            peak.force, peak.torque))
end)
