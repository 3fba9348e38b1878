-- Damped-least-squares inverse kinematics for a modular arm (worlds/arm_ik.lua), closed on the
-- measured joint angles. Every module of the arm runs this file:
--   - each SuperBot puts its measured joint angles, stamped with the time, into a table it floods
--     along the chain (`front` and `back` docks) every step; the elongated docks only relay, so
--     news travels one hop per step;
--   - the controller (params.controller) runs the IK each step on one consistent snapshot of
--     the measured angles (its own taken from the time the others' were): forward kinematics
--     (lua/kinematics.lua, from the module types' data), the tip's error to the current target
--     (clipped to 3 cm), and one damped-least-squares step (linalg's A:dls) whose damping grows
--     as the tip Jacobian's smallest singular value falls (near a singularity). Servos whose
--     static gravity torque (from the model's masses) is above 35% of their rating add rows
--     asking for it to come down, solved with the tip's rows (9 joints leave room for both), so
--     the arm stays where the servos hold it easily (a move that stalls, the two kinds of rows
--     pulling against each other, may go up to 50% until it progresses again). Joints that
--     would pass a limit are taken out and the step solved again;
--   - the command integrates the step (command += 0.1 x step, at most 0.3 rad/s, at most
--     0.15 rad ahead of the measured angle, within the limits). Because the step comes from the
--     measured pose, whatever the servos leave undone (sag under load, latency) keeps moving the
--     command until the measured tip is on target. Commanding "measured + step" directly fed
--     the late angles back into the servos and chattered; faster commands made the lower servos
--     saturate accelerating the arm (2.2 kg above them) and let it fall;
--   - the commands flood back the same way and each SuperBot drives its servos to its own.
-- params: structure = {modules = {{name=, type=}}, connections = {...}, base=, base_pose=} (as
-- kinematics.structure, with type names), tip = {module, dock}, controller = module name,
-- targets = {{x, y, z}, ...}, start = s, slot = s (target k is active from start + (k-1) slot).
local linalg = require("linalg")
local kin = require("kinematics")
local arm = require("arm_control")

local kLambdaMin = 0.002   -- m: damping always present
local kLambdaMax = 0.04    -- m: damping at a singularity
local kSigmaZone = 0.04    -- m: damping grows as the smallest singular value falls below this
local kMaxError = 0.03     -- m: larger errors are clipped (the linearisation holds)
local kLoadFree = 0.35     -- fraction of a servo's rating its static gravity load should stay under
local kLoadStalled = 0.5   -- ... or under this, while a move is stalled
local kStallTime = 0.5     -- s without the error falling by a fifth: stalled
local kLoadWeight = 0.5    -- m per unit of rating: weight of the load rows against the tip's
local kMaxLoadStep = 0.05  -- fraction of a rating: largest load correction asked in one step
local kLimitMargin = 0.05  -- rad kept clear of the joint limits

local me = module.name
local joints = {}
for _, name in ipairs(module.joints()) do joints[#joints + 1] = { name = name, j = module.joint(name) } end
local chainDocks = {}
for _, d in ipairs({ "front", "back" }) do
  if module.has_sensor("dock:" .. d) then chainDocks[#chainDocks + 1] = module.dock(d) end
end

local angles, commands = {}, {}  -- module name -> {t = time, joint name = angle, ...}
local history = {}                -- the controller's own angles, newest first (a few steps)

-- The controller's model, built once from the module types' data.
local ctl
if me == params.controller then
  local mods = {}
  for i, m in ipairs(params.structure.modules) do mods[i] = { name = m.name, type = module.type_data(m.type) } end
  local s = kin.structure{ modules = mods, connections = params.structure.connections,
                           base = params.structure.base, base_pose = params.structure.base_pose }
  local n = #s.dofs
  local lo, hi = {}, {}
  for i, d in ipairs(s.dofs) do
    lo[i] = d.continuous and -math.huge or d.lower + kLimitMargin
    hi[i] = d.continuous and math.huge or d.upper - kLimitMargin
  end
  ctl = { s = s, n = n, lo = lo, hi = hi, cmd = {}, best = math.huge, since = 0 }
end

local function currentTarget(t)
  local k = math.floor((t - params.start) / params.slot) + 1
  if k < 1 then return nil end
  return params.targets[math.min(k, #params.targets)]
end

--- One IK step from measured angles q (array by dof); returns the commands (array by dof), the
--- tip's distance to the target, the damping and the largest static load (fraction of a rating).
local function ikStep(q, target, dt)
  local f = ctl.s:fk(q)
  local Jt, p = f:jacobian(params.tip[1], params.tip[2])
  local e = { target[1] - p[1], target[2] - p[2], target[3] - p[3] }
  local en = math.sqrt(e[1] ^ 2 + e[2] ^ 2 + e[3] ^ 2)
  if en > kMaxError then for i = 1, 3 do e[i] = e[i] * kMaxError / en end end
  -- Adaptive damping from the tip Jacobian's smallest singular value (Maciejewski/Nakamura).
  local lambda = arm.damping(Jt, kLambdaMin, kLambdaMax, kSigmaZone)
  -- Static loads: a servo whose gravity torque (from the model's masses) is above kLoadFree of its
  -- rating adds a row asking for it to come back under, solved together with the tip's rows
  -- (with 9 joints and 3 tip coordinates there is room for both); its gradient comes from
  -- finite differences of the model.
  -- A move that makes no progress for kStallTime (the tip and the load rows pulling against
  -- each other) may load the servos up to kLoadStalled until it does.
  local now = sim.time()
  if en < 0.8 * ctl.best or en > ctl.best + 0.05 then ctl.best, ctl.since = en, now end
  local loadFree = (now - ctl.since > kStallTime and en > 0.002) and kLoadStalled or kLoadFree
  local tau = ctl.s:gravity(q)
  local rows, rhs = { Jt[1], Jt[2], Jt[3] }, { e[1], e[2], e[3] }
  local worst, active = 0, {}
  for i = 1, ctl.n do
    local frac = tau[i] / ctl.s.dofs[i].torque
    worst = math.max(worst, math.abs(frac))
    if math.abs(frac) > loadFree then active[#active + 1] = { i, frac } end
  end
  if #active > 0 then
    local dtau = {}
    for j = 1, ctl.n do
      local qj = q[j]
      q[j] = qj + 1e-5
      dtau[j] = ctl.s:gravity(q)
      q[j] = qj
    end
    for _, a in ipairs(active) do
      local i, frac = a[1], a[2]
      local rating = ctl.s.dofs[i].torque
      local row = {}
      for j = 1, ctl.n do row[j] = kLoadWeight * (dtau[j][i] - tau[i]) / 1e-5 / rating end
      local over = frac - (frac > 0 and loadFree or -loadFree)
      rows[#rows + 1] = row
      rhs[#rhs + 1] = -kLoadWeight * math.max(-kMaxLoadStep, math.min(kMaxLoadStep, over))
    end
  end
  local A = linalg.matrix(rows)
  local b = linalg.vector(rhs)
  -- Joints at a limit and pushed further are taken out and the step solved again.
  local dq = arm.solve_within(A, b, lambda, q, ctl.lo, ctl.hi)
  -- The command integrates the step: command += gain * step, with the step computed from the
  -- measured pose, so whatever the servos leave undone (sag under load, latency) keeps moving the
  -- command until the measured tip is on target. Commanding "measured + step" directly fed the
  -- late-arriving angles back into the servos and chattered; the integrated command is smooth.
  -- It is kept within a window of the measured angle (a saturated servo cannot wind it up);
  -- lua/arm_control.lua holds the gain, window and rate.
  local cmd = ctl.cmd
  for i = 1, ctl.n do cmd[i] = arm.command(cmd[i], q[i], dq:get(i), ctl.lo[i], ctl.hi[i], dt) end
  return cmd, en, lambda, worst
end

function step(dt)
  local t = sim.time()
  local msg = module.receive()
  while msg do
    if type(msg.data) == "table" then
      arm.merge(angles, msg.data.a)
      arm.merge(commands, msg.data.c)
    end
    msg = module.receive()
  end
  if #joints > 0 then
    local mine = { t = t }
    for _, j in ipairs(joints) do mine[j.name] = j.j:angle() end
    angles[me] = mine
    if ctl then
      table.insert(history, 1, mine)
      history[9] = nil
    end
  end
  if ctl then
    local target = currentTarget(t)
    local complete = true
    for _, d in ipairs(ctl.s.dofs) do
      if not (angles[d.module] and angles[d.module][d.joint]) then complete = false end
    end
    if target and complete then
      -- One snapshot: the others' angles arrive a few steps late, so this module's own are taken
      -- from the same time (kept in `history`), and the model sees one consistent pose.
      local oldest = t
      for name, rec in pairs(angles) do
        if name ~= me then oldest = math.min(oldest, rec.t) end
      end
      local own = angles[me]
      for _, rec in ipairs(history) do
        if rec.t <= oldest + 1e-9 then
          own = rec
          break
        end
      end
      local q = {}
      for i, d in ipairs(ctl.s.dofs) do q[i] = (d.module == me and own or angles[d.module])[d.joint] end
      local cmd, err, lambda, gravityLoad = ikStep(q, target, dt)
      for i, d in ipairs(ctl.s.dofs) do
        local c = commands[d.module]
        if not c or c.t ~= t then
          c = { t = t }
          commands[d.module] = c
        end
        c[d.joint] = cmd[i]
      end
      module.trace("ik_error_mm", err * 1000)
      module.trace("lambda", lambda)
      module.trace("static_load", gravityLoad)
    end
  end
  local c = commands[me]
  if c then
    for _, j in ipairs(joints) do
      if c[j.name] then j.j:set_target(c[j.name]) end
    end
  end
  local out = { a = angles, c = commands }
  for _, d in ipairs(chainDocks) do
    if d:engaged() then d:send(out) end
  end
end
