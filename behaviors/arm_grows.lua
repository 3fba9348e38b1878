-- The growing arm (worlds/arm_grows.lua): a SuperBot arm hanging from a fixed base finds a free
-- SuperBot by its tip dock's proximity reading, docks to it with IK, and reaches farther with it.
-- Every module of the arm and the free module run this file:
--   - the arm's SuperBots flood their measured joint angles along their engaged docks every step
--     and the commands come back the same way (as behaviors/arm_ik.lua); the elongated docks
--     relay. Docks the arm does not use are disabled, so the only free dock the tip can sense is
--     the one the free module offers;
--   - the free module (params.free) holds its joints straight and keeps only its `back` dock
--     enabled; once docked it introduces itself over the dock (name, type, its dock, the peer's
--     id and dock) and joins the flooding;
--   - the controller (params.controller, the SuperBot whose `front` dock is the tip) runs the
--     phases, all from its own sensing: the arm's kinematics (lua/kinematics.lua) on the
--     measured angles gives the tip, and the tip dock's `proximity` gives the distance to the
--     free dock (nil beyond 0.1 m):
--       search   the tip, pointing down, goes out and follows circles inwards round the base's
--                axis until the reading appears;
--       probe    it moves round a small pattern there; every step with a reading adds a sample
--                (tip position, distance) and the free dock's centre is trilaterated from all
--                samples by least squares (|p|^2 - d^2 = 2 p.c - |c|^2, linear in c and |c|^2);
--       approach the tip, pointing down, moves over the estimate (the estimate keeps being
--                refined), coming in from outside, where its kinematics holds it higher; the
--                free dock is a little below where it ends, and the magnet latches the faces;
--       grown    the newcomer's introduction adds it to the model (its joints become dofs), the
--                tip moves to its `front` dock, lifts it off its stand and reaches params.goal.
--     The tip's orientation is controlled while docking (three points of the tip frame: the
--     dock centre and points along its normal and up), so the faces meet square: the free
--     modules stand on the lattice with their offered dock facing up and its `up` along
--     params.lattice_up (known to the arm: where the module is, it learns by sensing).
-- params: structure (as kinematics.structure, with type names), controller, free = true on the
-- free module, start (s), search = {center = {x, y}, radii = {m...}, start = rad}, lattice_up,
-- goal = {x, y, z}, lift (m).
local linalg = require("linalg")
local kin = require("kinematics")
local arm = require("arm_control")
local vec = require("vec")

local kLambdaMin = 0.003   -- m: damping always present
local kLambdaMax = 0.04    -- m: damping at a singularity
local kSigmaZone = 0.04    -- m: damping grows as the smallest singular value falls below this
local kMaxError = 0.03     -- m: larger errors are clipped
local kPosture = 0.01      -- m/rad: weight of the pull towards straight
local kFrameArm = 0.05     -- m: the orientation points' distance from the dock centre
local kLimitMargin = 0.05  -- rad kept clear of the joint limits
local kSpeed = 0.06        -- m/s: the moving target's speed (search, probe, approach)
local kRelease = 0.01      -- m: the free module lets go of its station when the arm's dock is this near
local kProbe = 0.025       -- m: size of the probe pattern

local me = module.name
local joints = {}
for _, name in ipairs(module.joints()) do joints[#joints + 1] = { name = name, j = module.joint(name) } end

local angles, commands, hellos = {}, {}, {}
local history = {}     -- the controller's own angles, newest first
local proxHistory = {} -- the controller's tip readings, newest first: {t, distance or false}
local joined = false   -- the free module: docked to the arm
local released = false -- the free module: has let go of its station

local v3, sub, add, scale, norm = vec.v3, vec.sub, vec.add, vec.scale, vec.norm

local ctl

--- The controller's model from a structure description (type names).
local function buildModel(structure, tip)
  local mods = {}
  for i, m in ipairs(structure.modules) do mods[i] = { name = m.name, type = module.type_data(m.type) } end
  local s = kin.structure{ modules = mods, connections = structure.connections, base = structure.base,
                           base_pose = structure.base_pose }
  local lo, hi = {}, {}
  for i, d in ipairs(s.dofs) do
    lo[i] = d.continuous and -math.huge or d.lower + kLimitMargin
    hi[i] = d.continuous and math.huge or d.upper - kLimitMargin
  end
  local d = s.modules[tip[1]].dock(tip[2])
  return { s = s, n = #s.dofs, lo = lo, hi = hi, tip = tip, at = v3(d.at), normal = v3(d.normal), up = v3(d.up) }
end

--- A path through points, followed at kSpeed from time t0: the point at time t.
local function pathAt(points, t0, t)
  local left = math.max(0, t - t0) * kSpeed
  for i = 2, #points do
    local seg = norm(sub(points[i], points[i - 1]))
    if left <= seg then return add(points[i - 1], scale(sub(points[i], points[i - 1]), left / seg)), false end
    left = left - seg
  end
  return points[#points], true
end

--- The search path: from the centre out to the outer circle, then circles inwards (radii from
--- params.search.radii), points every 30 degrees, starting at angle params.search.start.
local function spiral(sp)
  local c = sp.center
  local pts = { { c[1], c[2], 0 } }
  for k, r in ipairs(sp.radii) do
    for i = 0, 12 do
      local a = sp.start + (k % 2 == 1 and 1 or -1) * i * math.pi / 6
      pts[#pts + 1] = { c[1] + r * math.cos(a), c[2] + r * math.sin(a), 0 }
    end
  end
  return pts
end

if me == params.controller then
  local structure = { modules = {}, connections = {}, base = params.structure.base,
                      base_pose = params.structure.base_pose }
  for i, m in ipairs(params.structure.modules) do structure.modules[i] = m end
  for i, c in ipairs(params.structure.connections) do structure.connections[i] = c end
  ctl = { structure = structure, model = buildModel(structure, { me, "front" }), cmd = {}, phase = "wait",
          samples = {}, lattice_up = v3(params.lattice_up), down = { 0, 0, -1 } }
end

--- The free dock's centre from the samples (tip position, distance), by linear least squares;
--- nil while they do not fix it (fewer than 6, or all in a plane).
local function trilaterate(samples)
  if #samples < 6 then return nil end
  local rows, rhs = {}, {}
  for i, smp in ipairs(samples) do
    local p, d = smp[1], smp[2]
    rows[i] = { 2 * p[1], 2 * p[2], 2 * p[3], -1 }
    rhs[i] = p[1] ^ 2 + p[2] ^ 2 + p[3] ^ 2 - d * d
  end
  local A = linalg.matrix(rows)
  local _, sv = A:svd()
  if sv:get(4) < 1e-4 * sv:get(1) then return nil end
  local x = A:pinv() * linalg.vector(rhs)
  return { x:get(1), x:get(2), x:get(3) }
end

--- One IK step from measured angles q towards `target` (the tip dock's centre). mode "pose":
--- the tip's normal and up are driven to ctl.down and ctl.lattice_up too; "level": the same
--- without the height (the tip's height is left to the arm: pointing down, a hanging 6-joint
--- arm can move its tip up only by rolling its SuperBots far); "position": the centre only.
local function ikStep(q, target, mode, dt)
  local m = ctl.model
  local f = m.s:fk(q)
  local J, p = f:jacobian(m.tip[1], m.tip[2])
  local e = sub(target, p)
  if mode == "level" then e[3] = 0 end
  local en = norm(e)
  if en > kMaxError then e = scale(e, kMaxError / en) end
  local lambda = arm.damping(J, kLambdaMin, kLambdaMax, kSigmaZone)
  local rows, rhs = { J[1], J[2] }, { e[1], e[2] }
  if mode ~= "level" then
    rows[3], rhs[3] = J[3], e[3]
  end
  if mode ~= "position" then
    for _, pair in ipairs({ { m.normal, ctl.down }, { m.up, ctl.lattice_up } }) do
      local Jk, pk = f:jacobian(m.tip[1], m.tip[2], add(m.at, scale(pair[1], kFrameArm)))
      local ek = sub(add(e, scale(pair[2], kFrameArm)), sub(pk, p))
      for r = 1, 3 do
        rows[#rows + 1] = Jk[r]
        rhs[#rhs + 1] = ek[r]
      end
    end
  end
  -- A weak pull of every joint towards straight keeps the arm in its plain shape where the task
  -- leaves it free (without it, pointing down with the height free, the rolls wandered to their
  -- limits).
  for i = 1, m.n do
    local row = {}
    for j = 1, m.n do row[j] = 0 end
    row[i] = kPosture
    rows[#rows + 1] = row
    rhs[#rhs + 1] = -kPosture * q[i]
  end
  local A, b = linalg.matrix(rows), linalg.vector(rhs)
  local dq = arm.solve_within(A, b, lambda, q, m.lo, m.hi)
  local cmd = ctl.cmd
  for i, d in ipairs(m.s.dofs) do
    local key = d.module .. "." .. d.joint
    cmd[key] = arm.command(cmd[key], q[i], dq:get(i), m.lo[i], m.hi[i], dt)
  end
  return p
end

--- The newcomer's introduction: add it to the model, docked at the tip; the tip moves to its
--- dock opposite the one it docked by.
local function grow(h)
  local st = ctl.structure
  st.modules[#st.modules + 1] = { name = h.name, type = h.type }
  st.connections[#st.connections + 1] = { me, h.peer_dock, h.name, h.dock, 0 }
  local far = h.dock == "front" and "back" or "front"
  ctl.model = buildModel(st, { h.name, far })
  ctl.phase, ctl.t0 = "lift", sim.time()
end

--- The controller's phases (see the top of the file); returns the target and the IK mode.
local function plan(t, p, reading)
  if ctl.phase == "wait" then
    if t < params.start then return nil end
    ctl.path, ctl.phase, ctl.t0 = spiral(params.search), "search", t
  end
  if reading and (ctl.phase == "search" or ctl.phase == "probe" or ctl.phase == "approach"
                  or ctl.phase == "descend") then
    ctl.samples[#ctl.samples + 1] = { p, reading }
    if #ctl.samples > 400 then table.remove(ctl.samples, 1) end
    ctl.estimate = trilaterate(ctl.samples) or ctl.estimate
  end
  if ctl.phase == "search" then
    if not reading then
      local target, done = pathAt(ctl.path, ctl.t0, t)
      if done then ctl.phase = "lost" end
      return target, "level"
    end
    -- Found: a small pattern round here gives samples off any one plane: up, to either side
    -- and towards the axis (at half the height), all above where the reading appeared.
    local k, h = kProbe, kProbe
    local inward = scale({ p[1], p[2], 0 }, -1 / math.max(1e-6, norm({ p[1], p[2], 0 })))
    local side = { -inward[2], inward[1], 0 }
    ctl.path = { p, add(p, { 0, 0, h }), add(p, add(scale(side, k), { 0, 0, h })),
                 add(p, add(scale(inward, k), { 0, 0, h / 2 })), add(p, add(scale(side, -k), { 0, 0, h })),
                 add(p, { 0, 0, h }) }
    ctl.phase, ctl.t0 = "probe", t
    module.publish("found_at", t)
  end
  if ctl.phase == "probe" then
    local target, done = pathAt(ctl.path, ctl.t0, t)
    if not done or not ctl.estimate then return target, "position" end
    ctl.phase = "approach"
  end
  if ctl.phase == "approach" then
    -- Over the free dock: pointing down, the tip's height is where the arm's kinematics puts
    -- it; the free dock stands just below that, so the faces meet from above.
    if module.dock("front"):engaged() then
      ctl.phase = "joined"
      return nil
    end
    local e = sub(ctl.estimate, p)
    if math.sqrt(e[1] ^ 2 + e[2] ^ 2) < 0.001 then
      ctl.close = ctl.close or t
      if t - ctl.close > 1 then return ctl.estimate, "pose" end
    end
    return ctl.estimate, "level"
  end
  if ctl.phase == "joined" then return nil end
  if ctl.phase == "lift" then
    ctl.lift_from = ctl.lift_from or p
    if t - ctl.t0 > params.lift_time then ctl.phase = "reach" end
    return add(ctl.lift_from, { 0, 0, params.lift }), "position"
  end
  if ctl.phase == "reach" then return v3(params.goal), "position" end
  return nil
end

function init()
  -- Only the docks in use stay enabled: the arm's engaged ones and its tip; the free module's
  -- offered dock.
  for _, name in ipairs(module.docks()) do
    local d = module.dock(name)
    local keep
    if params.free then
      keep = name == params.offer or name == params.release
    else
      keep = d:engaged() or (me == params.controller and name == "front")
    end
    if not keep then d:disable() end
  end
end

function on_dock(dock, event)
  local name = type(dock) == "string" and dock or dock:name()
  if params.free and event == "engaged" and name == params.offer then
    joined = name
  end
end

function step(dt)
  local t = sim.time()
  local msg = module.receive()
  while msg do
    if type(msg.data) == "table" then
      arm.merge(angles, msg.data.a)
      arm.merge(commands, msg.data.c)
      for name, h in pairs(msg.data.h or {}) do hellos[name] = h end
    end
    msg = module.receive()
  end
  if #joints > 0 then
    local mine = { t = t }
    for _, j in ipairs(joints) do mine[j.name] = j.j:angle() end
    angles[me] = mine
  end
  if params.free and params.release and not released then
    -- Let go of the station just before the arm's dock arrives (its own dock's proximity
    -- reading): letting go once latched, with the arm and the station both holding it, jerked
    -- the new connection past its strength.
    local r = module.sensor("dock:" .. params.offer)
    if joined or (r and r.proximity and r.proximity < kRelease) then
      module.dock(params.release):disable()
      released = true
    end
  end
  if params.free and joined then
    local pid, pdock = module.dock(joined):peer()
    hellos[me] = { name = me, type = module.type, dock = joined, peer_id = pid, peer_dock = pdock }
  end
  if ctl then
    table.insert(history, 1, angles[me])
    history[9] = nil
    local reading = module.sensor("dock:front")
    table.insert(proxHistory, 1, { t, reading and reading.proximity or false })
    proxHistory[9] = nil
    for _, h in pairs(hellos) do
      if h.peer_id == module.id and ctl.phase == "joined" then grow(h) end
    end
    local complete = true
    for _, d in ipairs(ctl.model.s.dofs) do
      if not (angles[d.module] and angles[d.module][d.joint]) then complete = false end
    end
    if complete then
      -- One consistent snapshot: the others' angles arrive a few steps late; this module's own
      -- angles and its tip reading are taken from that time.
      local oldest = t
      for name, rec in pairs(angles) do
        if name ~= me then oldest = math.min(oldest, rec.t) end
      end
      local own, prox = angles[me], false
      for i, rec in ipairs(history) do
        if rec.t <= oldest + 1e-9 then
          own, prox = rec, proxHistory[i][2]
          break
        end
      end
      local q = {}
      for i, d in ipairs(ctl.model.s.dofs) do q[i] = (d.module == me and own or angles[d.module])[d.joint] end
      local p = ctl.model.s:fk(q):dock(ctl.model.tip[1], ctl.model.tip[2])
      local target, mode = plan(t, p, prox or nil)
      if target then
        ikStep(q, target, mode, dt)
        for i, d in ipairs(ctl.model.s.dofs) do
          local c = commands[d.module]
          if not c or c.t ~= t then
            c = { t = t }
            commands[d.module] = c
          end
          c[d.joint] = ctl.cmd[d.module .. "." .. d.joint]
        end
        module.trace("tip_error_mm", norm(sub(target, p)) * 1000)
      end
      if ctl.phase ~= ctl.published then
        module.publish("phase", ctl.phase)
        ctl.published = ctl.phase
      end
      if ctl.estimate then module.publish("estimate", ctl.estimate) end
      module.publish("samples", #ctl.samples)
      module.publish("dofs", ctl.model.n)
    end
  end
  local c = commands[me]
  if c and (not params.free or joined) then
    for _, j in ipairs(joints) do
      if c[j.name] then j.j:set_target(c[j.name]) end
    end
  elseif params.free then
    for _, j in ipairs(joints) do j.j:set_target(0) end
  end
  local out = { a = angles, c = commands, h = hellos }
  for _, name in ipairs(module.docks()) do
    local d = module.dock(name)
    if d:engaged() then d:send(out) end
  end
end
