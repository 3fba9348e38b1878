-- Forward kinematics of a connected structure of modules, built from the module types' own data
-- (world.module_type(name) in world scripts, module.type_data(name) in behaviours), so it stays
-- right when a type file changes: joint pivots and axes, dock frames, and the mating rule of
-- world.connect (faces opposite, turned orientation * 360/symmetry degrees about the normal).
--
--   local kin = require("kinematics")
--   local s = kin.structure{
--     modules = { {name = "base", type = world.module_type("elongated_dock")},
--                 {name = "sb1", type = world.module_type("superbot")}, ... },
--     connections = { {"base", "front", "sb1", "back", 0}, ... },  -- as world.connect(a, da, b, db, o)
--     base = "base",                                     -- its module frame is placed at base_pose
--     base_pose = { at = {0, 0, 0.05}, quat = {1, 0, 0, 0} },
--   }
--   s.dofs                        -- {{module=, joint=, lower=, upper=, torque=}, ...}: the joints in
--                                 -- order from the base outwards (connection order breaks ties)
--   local f = s:fk(q)             -- q: angles by dof index (q[i]) -- or by s:angles_from(tbl)
--   f:link(module, link)          -- position {x,y,z}, rotation (3x3 row-major, 9 numbers)
--   f:link_pose(module, link)     -- {x,y,z}, {w,x,y,z}
--   f:dock(module, dock)          -- centre and outward normal, {x,y,z} each
--   f:jacobian(module, dock [, point]) -- 3 x ndof position Jacobian of the dock centre (or of a
--                                 -- point in that dock's link frame): rows of plain numbers
--   s:gravity(q, g)               -- static joint torques (N m, per dof, motor's sign) and dock
--                                 -- loads ({force=, torque=} per connection) under gravity g
--                                 -- ({0, 0, -9.81} default) with the base held
-- Rotations are 3x3 row-major arrays of 9 numbers; vectors {x, y, z}. A loop (a second path
-- between two links) is ignored: the tree found from the base decides.
local K = {}

-- ---------- small rotation algebra ----------

local function rmul(a, b)
  return {
    a[1] * b[1] + a[2] * b[4] + a[3] * b[7], a[1] * b[2] + a[2] * b[5] + a[3] * b[8], a[1] * b[3] + a[2] * b[6] + a[3] * b[9],
    a[4] * b[1] + a[5] * b[4] + a[6] * b[7], a[4] * b[2] + a[5] * b[5] + a[6] * b[8], a[4] * b[3] + a[5] * b[6] + a[6] * b[9],
    a[7] * b[1] + a[8] * b[4] + a[9] * b[7], a[7] * b[2] + a[8] * b[5] + a[9] * b[8], a[7] * b[3] + a[8] * b[6] + a[9] * b[9],
  }
end

local function rvec(a, v)
  return { a[1] * v[1] + a[2] * v[2] + a[3] * v[3], a[4] * v[1] + a[5] * v[2] + a[6] * v[3],
           a[7] * v[1] + a[8] * v[2] + a[9] * v[3] }
end

local function rt(a)
  return { a[1], a[4], a[7], a[2], a[5], a[8], a[3], a[6], a[9] }
end

local function axisAngle(u, q)
  local c, s = math.cos(q), math.sin(q)
  local t = 1 - c
  local x, y, z = u[1], u[2], u[3]
  return {
    t * x * x + c, t * x * y - s * z, t * x * z + s * y,
    t * x * y + s * z, t * y * y + c, t * y * z - s * x,
    t * x * z - s * y, t * y * z + s * x, t * z * z + c,
  }
end

local function quatToR(q)
  local w, x, y, z = q[1] or q.w, q[2] or q.x, q[3] or q.y, q[4] or q.z
  local n = math.sqrt(w * w + x * x + y * y + z * z)
  w, x, y, z = w / n, x / n, y / n, z / n
  return {
    1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
  }
end

local function rToQuat(r)
  local tr = r[1] + r[5] + r[9]
  local w, x, y, z
  if tr > 0 then
    local s = math.sqrt(tr + 1) * 2
    w, x, y, z = s / 4, (r[8] - r[6]) / s, (r[3] - r[7]) / s, (r[4] - r[2]) / s
  elseif r[1] > r[5] and r[1] > r[9] then
    local s = math.sqrt(1 + r[1] - r[5] - r[9]) * 2
    w, x, y, z = (r[8] - r[6]) / s, s / 4, (r[2] + r[4]) / s, (r[3] + r[7]) / s
  elseif r[5] > r[9] then
    local s = math.sqrt(1 + r[5] - r[1] - r[9]) * 2
    w, x, y, z = (r[3] - r[7]) / s, (r[2] + r[4]) / s, s / 4, (r[6] + r[8]) / s
  else
    local s = math.sqrt(1 + r[9] - r[1] - r[5]) * 2
    w, x, y, z = (r[4] - r[2]) / s, (r[3] + r[7]) / s, (r[6] + r[8]) / s, s / 4
  end
  if w < 0 then w, x, y, z = -w, -x, -y, -z end
  return { w, x, y, z }
end

local function add(a, b) return { a[1] + b[1], a[2] + b[2], a[3] + b[3] } end
local function sub(a, b) return { a[1] - b[1], a[2] - b[2], a[3] - b[3] } end
local function cross(a, b)
  return { a[2] * b[3] - a[3] * b[2], a[3] * b[1] - a[1] * b[3], a[1] * b[2] - a[2] * b[1] }
end
local function dot(a, b) return a[1] * b[1] + a[2] * b[2] + a[3] * b[3] end
local function v3(t) return { t[1] or t.x, t[2] or t.y, t[3] or t.z } end

K.rmul, K.rvec, K.rt, K.axis_angle, K.quat_to_R, K.R_to_quat = rmul, rvec, rt, axisAngle, quatToR, rToQuat
K.cross, K.dot, K.add, K.sub = cross, dot, add, sub

-- ---------- the structure ----------

local Structure = {}
Structure.__index = Structure
local Frames = {}
Frames.__index = Frames

local function index(list, what, owner)
  local out = {}
  for i, e in ipairs(list or {}) do out[e.name] = e end
  return function(name)
    local e = out[name]
    if not e then error(string.format("kinematics: %s has no %s named '%s'", owner, what, tostring(name)), 3) end
    return e
  end
end

--- Builds the structure (see the top of this file).
function K.structure(def)
  assert(type(def) == "table", "kinematics.structure: expected a table")
  local mods, order = {}, {}
  for i, m in ipairs(def.modules or {}) do
    assert(type(m.name) == "string" and type(m.type) == "table",
           "kinematics.structure: modules[" .. i .. "] needs name= and type= (a module type's data)")
    local t = m.type
    local rec = { name = m.name, type = t, link = index(t.links, "link", t.name), dock = index(t.docks, "dock", t.name),
                  joints = {}, edges = {} }
    for _, l in ipairs(t.links) do rec.edges[l.name] = {} end
    for _, j in ipairs(t.joints or {}) do
      table.insert(rec.edges[j.parent], { kind = "joint", joint = j, to = j.child, sign = 1 })
      table.insert(rec.edges[j.child], { kind = "joint", joint = j, to = j.parent, sign = -1 })
    end
    mods[m.name] = rec
    order[#order + 1] = rec
  end
  for i, c in ipairs(def.connections or {}) do
    local a, b = mods[c[1]], mods[c[3]]
    assert(a and b, "kinematics.structure: connections[" .. i .. "] names an unknown module")
    local da, db = a.dock(c[2]), b.dock(c[4])
    local sym = math.max(1, math.min(da.symmetry or 4, db.symmetry or 4))
    local theta = 2 * math.pi * ((c[5] or 0) % sym) / sym
    -- partner dock frame = dock frame * Rx(theta) * Rz(pi); the relation is symmetric
    local mate = rmul(axisAngle({ 1, 0, 0 }, theta), { -1, 0, 0, 0, -1, 0, 0, 0, 1 })
    table.insert(a.edges[da.link], { kind = "dock", from = da, module = b, dock = db, mate = mate, index = i })
    table.insert(b.edges[db.link], { kind = "dock", from = db, module = a, dock = da, mate = mate, index = i })
  end
  local base = mods[def.base or (order[1] and order[1].name)]
  assert(base, "kinematics.structure: unknown base module")
  local bp = def.base_pose or {}
  local s = setmetatable({ modules = mods, order = order, base = base, dofs = {}, steps = {},
                           base_R = bp.quat and quatToR(bp.quat) or { 1, 0, 0, 0, 1, 0, 0, 0, 1 },
                           base_p = bp.at and v3(bp.at) or { 0, 0, 0 }, nconn = #(def.connections or {}) },
                         Structure)
  -- Breadth-first over (module, link) nodes from the base's root link: each step derives one
  -- node's frame from an earlier one.
  local seen = {}
  local function key(m, l) return m.name .. "\0" .. l end
  local queue = { { base, base.type.root } }
  seen[key(base, base.type.root)] = 1
  local head = 1
  s.nodes = { { module = base, link = base.type.root } }
  while head <= #queue do
    local m, l = queue[head][1], queue[head][2]
    local from = seen[key(m, l)]
    head = head + 1
    for _, e in ipairs(m.edges[l]) do
      local tm, tl = m, e.to
      if e.kind == "dock" then tm, tl = e.module, e.dock.link end
      if not seen[key(tm, tl)] then
        -- The joints and connections between a node and the base are found by walking `from`
        -- up the tree (a copy per node was quadratic: 1,000 chained SuperBots ran out of memory).
        local node = { module = tm, link = tl, from = from, edge = e }
        if e.kind == "joint" then
          local j = e.joint
          s.dofs[#s.dofs + 1] = { module = m.name, joint = j.name, lower = j.lower, upper = j.upper,
                                  torque = j.torque, continuous = j.continuous, sign = e.sign, node = from,
                                  pivot = j.pivot, axis = j.axis }
          node.dof = #s.dofs
        else
          node.conn = e.index
        end
        s.nodes[#s.nodes + 1] = node
        seen[key(tm, tl)] = #s.nodes
        queue[#queue + 1] = { tm, tl }
      end
    end
  end
  s.node_of = seen
  s.key = key
  return s
end

--- Angles by dof from a table {module_name = {joint_name = angle}} (missing ones: 0).
function Structure:angles_from(t)
  local q = {}
  for i, d in ipairs(self.dofs) do q[i] = (t[d.module] or {})[d.joint] or 0 end
  return q
end

--- Frames of every link at joint angles q (q[i] for self.dofs[i]).
function Structure:fk(q)
  local R, P = {}, {}
  R[1], P[1] = self.base_R, self.base_p
  for n = 2, #self.nodes do
    local node = self.nodes[n]
    local e = node.edge
    local pr, pp = R[node.from], P[node.from]
    if e.kind == "joint" then
      local j = e.joint
      local rj = axisAngle(j.axis, e.sign * (q[node.dof] or 0))
      -- T_child = T_parent * (Rj, pivot - Rj pivot) for angle sign * q
      R[n] = rmul(pr, rj)
      P[n] = add(pp, rvec(pr, sub(j.pivot, rvec(rj, j.pivot))))
    else
      local fa, fb = quatToR(e.from.quat), quatToR(e.dock.quat)
      local rd = rmul(rmul(pr, fa), e.mate)                -- partner dock frame in the world
      local pd = add(pp, rvec(pr, e.from.at))
      R[n] = rmul(rd, rt(fb))                              -- link = dock frame * inverse(dock in link)
      P[n] = sub(pd, rvec(R[n], e.dock.at))
    end
  end
  return setmetatable({ s = self, R = R, P = P, q = q }, Frames)
end

function Frames:node(module, link)
  local n = self.s.node_of[self.s.key(self.s.modules[module] or error("kinematics: no module '" ..
                                                                      tostring(module) .. "'", 3), link)]
  if not n then error("kinematics: link '" .. tostring(link) .. "' of '" .. module .. "' is not reached from the base", 3) end
  return n
end

--- Position and rotation (3x3 row-major) of a link frame.
function Frames:link(module, link)
  local n = self:node(module, link)
  return self.P[n], self.R[n]
end

--- Position {x,y,z} and quaternion {w,x,y,z} of a link frame.
function Frames:link_pose(module, link)
  local n = self:node(module, link)
  return self.P[n], rToQuat(self.R[n])
end

--- Centre and outward normal of a dock face.
function Frames:dock(module, dock)
  local d = self.s.modules[module].dock(dock)
  local n = self:node(module, d.link)
  return add(self.P[n], rvec(self.R[n], d.at)), rvec(self.R[n], d.normal)
end

--- 3 x ndof Jacobian of a dock centre (or `point`, in that dock's link frame) w.r.t. the dof
--- angles, and the point itself.
function Frames:jacobian(module, dock, point)
  local d = self.s.modules[module].dock(dock)
  local n = self:node(module, d.link)
  local p = add(self.P[n], rvec(self.R[n], point or d.at))
  local J = { {}, {}, {} }
  local ndof = #self.s.dofs
  for i = 1, ndof do J[1][i], J[2][i], J[3][i] = 0, 0, 0 end
  local nodes = self.s.nodes
  local k = n
  while k do
    local i = nodes[k].dof
    if i then
      local dof = self.s.dofs[i]
      local r, o = self.R[dof.node], self.P[dof.node]
      local axis = rvec(r, dof.axis)
      local pivot = add(o, rvec(r, dof.pivot))
      local c = cross(axis, sub(p, pivot))
      local sgn = dof.sign
      J[1][i], J[2][i], J[3][i] = sgn * c[1], sgn * c[2], sgn * c[3]
    end
    k = nodes[k].from
  end
  return J, p
end

--- Static joint torques (per dof: what the motor must give, N m, in the joint's own sign) and
--- dock loads (per connection index: {force=, torque=} in N and N m about the dock face) holding
--- the structure still against gravity g, the base held.
function Structure:gravity(q, g)
  g = g or { 0, 0, -9.81 }
  local f = self:fk(q)
  local torques, loads = {}, {}
  for i = 1, #self.dofs do torques[i] = 0 end
  for c = 1, self.nconn do loads[c] = { fvec = { 0, 0, 0 }, tvec = { 0, 0, 0 } } end
  -- centre of each connection's dock face (the one on the base's side)
  local connAt = {}
  for n = 2, #self.nodes do
    local e = self.nodes[n].edge
    if e.kind == "dock" then
      local from = self.nodes[n].from
      connAt[e.index] = add(f.P[from], rvec(f.R[from], e.from.at))
    end
  end
  for n = 1, #self.nodes do
    local node = self.nodes[n]
    local l = node.module.link(node.link)
    local w = { g[1] * l.mass, g[2] * l.mass, g[3] * l.mass }
    local com = add(f.P[n], rvec(f.R[n], l.com))
    local k = n
    while k do
      local up = self.nodes[k]
      local i, c = up.dof, up.conn
      if i then
        local dof = self.dofs[i]
        local r, o = f.R[dof.node], f.P[dof.node]
        local axis = rvec(r, dof.axis)
        local m = cross(sub(com, add(o, rvec(r, dof.pivot))), w)
        -- the motor holds the far side against gravity's moment
        torques[i] = torques[i] - dof.sign * dot(axis, m)
      end
      if c then
        local L = loads[c]
        L.fvec = add(L.fvec, w)
        L.tvec = add(L.tvec, cross(sub(com, connAt[c]), w))
      end
      k = up.from
    end
  end
  for c = 1, self.nconn do
    local L = loads[c]
    L.force = math.sqrt(dot(L.fvec, L.fvec))
    L.torque = math.sqrt(dot(L.tvec, L.tvec))
  end
  return torques, loads
end

return K
