-- Builds the 9-DOF modular arm of worlds/arm_ik.lua for world scripts (that world and
-- tests/worlds/arm_ik.lua share it), draws its targets and measures how well it reaches them.
--
--   local arm = require("arm_ik_world")
--   local a = arm.build{targets = 50, slot = 5}       -- or target = {x, y, z}; before the run
--   ... a.results() -> {errors = {m...}, settles = {s...}} once the run is over
--   arm.report(a)                                      -- metrics and a printed line (in on_end)
--
-- The arm: three SuperBots joined by two elongated docks stand on a third elongated dock held
-- fixed on end, its foot at the origin (so the base frame is the world frame, z up); every
-- module docks its `back` to the `front` of the one below; the tip is the top SuperBot's `front`
-- dock face. 9 joints, all +-90 deg, 2.5 N m, 3 rad/s.
--
-- Random targets are reachable and statically feasible: each is the tip of a random pose of the
-- kinematic model (lua/kinematics.lua, from the module types' data), every joint within
-- +-0.6 rad of upright, whose static gravity torques stay under a quarter of every servo's
-- rating and whose dock loads stay under a third of the docks' strength (100 N, 10 N m). Target
-- k holds from start + (k - 1) * slot for `slot` seconds; the tip's error at the end of the slot
-- and the time it first came within 1 mm for good are measured.
local kin = require("kinematics")
local M = {}

M.start = 0.5        -- s before the first target
M.tolerance = 0.001  -- m
M.spread = 0.6       -- rad: target poses within +-spread of upright on every joint
M.torque_share = 0.25  -- target poses: static torque under this share of each servo's rating
M.dock_share = 1 / 3   -- ... and dock loads under this share of the docks' strength

-- Bottom to top: module name, type, and the docks that join it to the one below.
M.layout = {
  { "base", "elongated_dock" },
  { "sb1", "superbot", "front", "back" },
  { "link1", "elongated_dock", "front", "back" },
  { "sb2", "superbot", "front", "back" },
  { "link2", "elongated_dock", "front", "back" },
  { "sb3", "superbot", "front", "back" },
}
M.tip = { "sb3", "front" }
M.controller = "sb2"  -- the middle SuperBot: two hops to either end
-- The base bar stands on end: its x axis (the bar) turned up, its foot on the ground.
M.base_quat = { math.cos(-math.pi / 4), 0, math.sin(-math.pi / 4), 0 }
M.base_at = { 0, 0, 0.05 }

--- The arm's kinematic model and the structure description the behaviour builds it from.
function M.model()
  local structure = { modules = {}, connections = {}, base = "base",
                      base_pose = { at = M.base_at, quat = M.base_quat } }
  local kmods = {}
  for i, m in ipairs(M.layout) do
    structure.modules[i] = { name = m[1], type = m[2] }
    kmods[i] = { name = m[1], type = world.module_type(m[2]) }
    if i > 1 then structure.connections[#structure.connections + 1] = { M.layout[i - 1][1], m[3], m[1], m[4], 0 } end
  end
  return kin.structure{ modules = kmods, connections = structure.connections, base = "base",
                        base_pose = structure.base_pose }, structure
end

--- n random reachable, statically feasible targets (math.random: the world's seed).
function M.draw_targets(model, n)
  local targets, tries = {}, 0
  while #targets < n do
    tries = tries + 1
    if tries > 1000 * n then error("arm_ik: could not draw " .. n .. " feasible targets", 2) end
    local q = {}
    for i = 1, #model.dofs do q[i] = (2 * math.random() - 1) * M.spread end
    local torques, loads = model:gravity(q)
    local ok = true
    for i, d in ipairs(model.dofs) do
      if math.abs(torques[i]) > M.torque_share * d.torque then ok = false end
    end
    for _, l in ipairs(loads) do
      if l.force > 100 * M.dock_share or l.torque > 10 * M.dock_share then ok = false end
    end
    if ok then
      local p = model:fk(q):dock(M.tip[1], M.tip[2])
      targets[#targets + 1] = { p[1], p[2], p[3] }
    end
  end
  return targets
end

--- Spawns the arm (exact solver) and sets up the measurement. opts: targets = N or target =
--- {x, y, z}, slot = seconds per target (default 5). Sets the world's duration.
function M.build(opts)
  world.set{solver = "exact"}
  local slot = opts.slot or 5
  local model, structure = M.model()
  local targets = opts.target and { opts.target } or M.draw_targets(model, opts.targets or 5)
  local mods = {}
  for i, m in ipairs(M.layout) do
    mods[i] = world.spawn(m[2], {
      name = m[1], fixed = (i == 1), at = i == 1 and M.base_at or nil, quat = i == 1 and M.base_quat or nil,
      behavior = "behaviors/arm_ik.lua",
      params = { structure = structure, tip = M.tip, controller = M.controller, targets = targets,
                 start = M.start, slot = slot },
    })
    if i > 1 then world.connect(mods[i - 1], M.layout[i][3], mods[i], M.layout[i][4]) end
  end
  world.set{duration = M.start + slot * #targets}
  local tipModule = mods[#mods]
  local errors, settles, within = {}, {}, {}
  local peak = { torque = 0, dock_torque = 0, dock_force = 0 }
  local function tipError(k)
    local p = tipModule:dock_position(M.tip[2])
    local t = targets[k]
    return math.sqrt((p.x - t[1]) ^ 2 + (p.y - t[2]) ^ 2 + (p.z - t[3]) ^ 2)
  end
  world.on_step(function(t)
    local k = math.floor((t - M.start) / slot + 1e-9) + 1
    if k < 1 or k > #targets then return end
    if tipError(k) < M.tolerance then
      within[k] = within[k] or (t - (M.start + (k - 1) * slot))
    else
      within[k] = nil
    end
    for _, m in ipairs(mods) do
      for name in pairs(m:joint_angles()) do peak.torque = math.max(peak.torque, math.abs(m:joint_torque(name))) end
    end
    for i = 1, #mods - 1 do
      local l = mods[i]:dock_load("front")
      if l then
        peak.dock_torque = math.max(peak.dock_torque, l.torque)
        peak.dock_force = math.max(peak.dock_force, l.force)
      end
    end
  end)
  for k = 1, #targets do
    world.at(M.start + k * slot - 1e-6, function()
      errors[k] = tipError(k)
      settles[k] = within[k] or slot
    end)
  end
  return { modules = mods, targets = targets, slot = slot, model = model, errors = errors, settles = settles,
           peak = peak }
end

--- Summary of the targets measured so far: count, within 1 mm, max and mean error (mm), mean and
--- max settling time (s).
function M.summary(a)
  local s = { n = #a.errors, reached = 0, max = 0, mean = 0, settle = 0, settle_max = 0 }
  for k = 1, s.n do
    local e = a.errors[k] * 1000
    s.max = math.max(s.max, e)
    s.mean = s.mean + e / s.n
    s.settle = s.settle + a.settles[k] / s.n
    s.settle_max = math.max(s.settle_max, a.settles[k])
    if a.errors[k] < M.tolerance then s.reached = s.reached + 1 end
  end
  return s
end

--- Reports the summary as metrics (ik_error_mm_max, ik_error_mm_mean, settle_time_s,
--- settle_time_s_max, reached_1mm, targets, peak loads) and on stdout.
function M.report(a)
  local s = M.summary(a)
  if s.n == 0 then return s end
  world.metric("ik_error_mm_max", s.max)
  world.metric("ik_error_mm_mean", s.mean)
  world.metric("settle_time_s", s.settle)
  world.metric("settle_time_s_max", s.settle_max)
  world.metric("reached_1mm", s.reached)
  world.metric("targets", s.n)
  world.metric("joint_torque_max", a.peak.torque)
  world.metric("dock_torque_max", a.peak.dock_torque)
  world.metric("dock_force_max", a.peak.dock_force)
  print(string.format("arm_ik: %d targets, %d within 1 mm; error max %.3f mm, mean %.3f mm; settled in %.2f s on"
                      .. " average, %.2f s at most; peak joint torque %.2f N m, dock loads %.1f N, %.2f N m",
                      s.n, s.reached, s.max, s.mean, s.settle, s.settle_max, a.peak.torque, a.peak.dock_force,
                      a.peak.dock_torque))
  return s
end

return M
