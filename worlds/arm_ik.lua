-- A 9-DOF modular arm reaching targets by damped least squares (the paper's Fig. 1(d), IV.C):
-- three SuperBots joined by two elongated docks stand on a fixed elongated dock (the base, its
-- foot at the origin, so the base frame is the world frame: z up). behaviors/arm_ik.lua runs the
-- IK in the middle SuperBot, closed on the measured joint angles that the modules pass along
-- their docks, in the physics, under gravity, within the servos' torque and speed limits, on the
-- exact joint solver.
--
--   rm3d run worlds/arm_ik.lua --param targets=50 [--seed N] [--param slot=2]
--   rm3d run worlds/arm_ik.lua --param target=0.1,0.05,0.7
--
-- Random targets are reachable and statically feasible: each is the tip of a random pose of the
-- kinematic model (lua/kinematics.lua, from the module types' data) whose static gravity torques
-- stay under 40% of every servo's rating and whose dock loads stay under a third of the docks'
-- strength. Each target holds for `slot` seconds; the tip's error at the end of the slot and
-- the time it took to come within 1 mm for good are reported as metrics (ik_error_mm_max,
-- ik_error_mm_mean, settle_time_s, settle_time_s_max, reached_1mm) and printed.
local kin = require("kinematics")

world.set{solver = "exact"}
world.ground{}

local kStart = 0.5                      -- s before the first target (the arm comes up to its pose)
local slot = tonumber(args.slot) or 2.0 -- s per target
local kTolerance = 0.001                -- m

-- The arm, bottom to top: module name, type, and the docks that join it to the one below.
local layout = {
  { "base", "elongated_dock" },
  { "sb1", "superbot", "front", "back" },
  { "link1", "elongated_dock", "front", "back" },
  { "sb2", "superbot", "front", "back" },
  { "link2", "elongated_dock", "front", "back" },
  { "sb3", "superbot", "front", "back" },
}
local tip = { "sb3", "front" }
-- The base bar stands on end: its x axis (the bar) turned up, its foot on the ground.
local baseQuat = { math.cos(-math.pi / 4), 0, math.sin(-math.pi / 4), 0 }
local baseAt = { 0, 0, 0.05 }

local structure = { modules = {}, connections = {}, base = "base", base_pose = { at = baseAt, quat = baseQuat } }
local kmods = {}
for i, m in ipairs(layout) do
  structure.modules[i] = { name = m[1], type = m[2] }
  kmods[i] = { name = m[1], type = world.module_type(m[2]) }
  if i > 1 then structure.connections[#structure.connections + 1] = { layout[i - 1][1], m[3], m[1], m[4], 0 } end
end
local model = kin.structure{ modules = kmods, connections = structure.connections, base = "base",
                             base_pose = structure.base_pose }

-- Targets: one from --param target=x,y,z, or N random feasible ones from the world's seed.
local targets = {}
if args.target then
  local x, y, z = tostring(args.target):match("^%s*([^,]+),([^,]+),([^,]+)%s*$")
  x, y, z = tonumber(x), tonumber(y), tonumber(z)
  if not (x and y and z) then error("--param target=x,y,z: expected three numbers (metres), got '" .. tostring(args.target) .. "'") end
  targets[1] = { x, y, z }
else
  local n = math.tointeger(tonumber(args.targets or 5))
  if not n or n < 1 or n > 10000 then error("--param targets=N: expected a whole number 1..10000, got " .. tostring(args.targets)) end
  local kSpread = 0.6        -- rad: poses drawn within +-kSpread of upright on every joint
  local tries = 0
  while #targets < n do
    tries = tries + 1
    if tries > 1000 * n then error("could not draw " .. n .. " feasible targets") end
    local q = {}
    for i = 1, #model.dofs do q[i] = (2 * math.random() - 1) * kSpread end
    local torques, loads = model:gravity(q)
    local ok = true
    for i, d in ipairs(model.dofs) do
      if math.abs(torques[i]) > 0.4 * d.torque then ok = false end
    end
    for _, l in ipairs(loads) do
      if l.force > 100 / 3 or l.torque > 10 / 3 then ok = false end
    end
    if ok then
      local p = model:fk(q):dock(tip[1], tip[2])
      targets[#targets + 1] = { p[1], p[2], p[3] }
    end
  end
end

local mods = {}
for i, m in ipairs(layout) do
  mods[i] = world.spawn(m[2], {
    name = m[1], fixed = (i == 1), at = i == 1 and baseAt or nil, quat = i == 1 and baseQuat or nil,
    behavior = "behaviors/arm_ik.lua",
    params = { debug = args.debug, structure = structure, tip = tip, controller = "sb2", targets = targets, start = kStart, slot = slot },
  })
  if i > 1 then world.connect(mods[i - 1], layout[i][3], mods[i], layout[i][4]) end
end
local tipModule = mods[#mods]
world.set{duration = kStart + slot * #targets}

-- Per target: the error at the end of its slot, and when it came within 1 mm for good.
local errors, settles = {}, {}
local within = {}    -- per target: when the tip came (and stayed) within tolerance in its slot
local worstTorque, worstDock = 0, 0
local function tipError(k)
  local p = tipModule:dock_position(tip[2])
  local t = targets[k]
  return math.sqrt((p.x - t[1]) ^ 2 + (p.y - t[2]) ^ 2 + (p.z - t[3]) ^ 2)
end
world.on_step(function(t)
  local k = math.floor((t - kStart) / slot + 1e-9) + 1
  if k < 1 or k > #targets then return end
  local slotStart = kStart + (k - 1) * slot
  local e = tipError(k)
  if e < kTolerance then
    within[k] = within[k] or (t - slotStart)
  else
    within[k] = nil
  end
  for _, m in ipairs(mods) do
    for name in pairs(m:joint_angles()) do worstTorque = math.max(worstTorque, math.abs(m:joint_torque(name))) end
  end
  local l = mods[1]:dock_load("front")
  if l then worstDock = math.max(worstDock, l.torque) end
end)
for k = 1, #targets do
  world.at(kStart + k * slot - 1e-6, function(t)
    errors[k] = tipError(k)
    if args.debug then
      local meas = {}
      for i, m in ipairs(mods) do meas[layout[i][1]] = m:joint_angles() end
      local p = model:fk(model:angles_from(meas)):dock(tip[1], tip[2])
      local tp = tipModule:dock_position(tip[2])
      local qq = model:angles_from(meas)
      local parts = {}
      for i = 1, #qq do parts[i] = string.format("%.5f", qq[i]) end
      print("world q " .. table.concat(parts, " "))
      print(string.format("target %d: world error %.3f mm, model-vs-world %.4f mm", k, errors[k] * 1000,
        1000 * math.sqrt((p[1] - tp.x) ^ 2 + (p[2] - tp.y) ^ 2 + (p[3] - tp.z) ^ 2)))
    end
    settles[k] = within[k] or slot
  end)
end

world.on_end(function(t)
  local n = #errors
  if n == 0 then return end
  local max, sum, smax, ssum, reached = 0, 0, 0, 0, 0
  for k = 1, n do
    max = math.max(max, errors[k])
    sum = sum + errors[k]
    smax = math.max(smax, settles[k])
    ssum = ssum + settles[k]
    if errors[k] < kTolerance then reached = reached + 1 end
  end
  world.metric("ik_error_mm_max", max * 1000)
  world.metric("ik_error_mm_mean", sum / n * 1000)
  world.metric("settle_time_s", ssum / n)
  world.metric("settle_time_s_max", smax)
  world.metric("reached_1mm", reached)
  world.metric("targets", n)
  world.metric("joint_torque_max", worstTorque)
  world.metric("base_dock_torque_max", worstDock)
  print(string.format("arm_ik: %d targets, %d within 1 mm; error max %.3f mm, mean %.3f mm; settle mean %.2f s, max %.2f s;"
                      .. " largest joint torque %.2f N m, base dock torque %.2f N m",
                      n, reached, max * 1000, sum / n * 1000, ssum / n, smax, worstTorque, worstDock))
end)
