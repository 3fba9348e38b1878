-- Lattice moves for ATRON self-reconfiguration, for behaviours (behaviors/reconfigure.lua): the
-- steps that carry out a plan of lua/reconfig.lua on ATRONs, and their executor.
--
-- An ATRON moves what hangs on one of its hemispheres by turning that hemisphere against the other
-- about its polar axis. A quarter turn leaves the carried modules' docks facing the rest of the
-- lattice male to male or female to female (assets/modules/atron.lua), so a move here is a half
-- turn: a carrier turns the hemisphere that a mover hangs on by 180 degrees, the mover arrives at
-- the lattice site where its dock faces the target module's, and the capture joint draws the two
-- together until they latch. Then the mover lets go of the carrier where the target shape has no
-- connection between them.
--
--   local moves = require("atron_moves")
--   local steps, why = moves.compile(now, target)   -- shapes (reconfig.shape)
--   print(moves.format(steps))
--   local exec = moves.new(net, steps)              -- net: lua/linkstate.lua
--   function step(dt) exec:step(net:receive()) ... net:send() ... if exec.done then ... end end
--
-- compile places every module from the connections alone, as world.connect places them, with
-- every equator at 0 (as the modules stand when they are connected), then, for each connection the
-- plan docks, finds a module that carries one end there in one half turn: the mover must hang on
-- that hemisphere through one connection only (nothing it carries may also hold the rest), and the
-- other end must stay. The half turns are simulated on the placed lattice, so a later move starts
-- from where the earlier ones left the modules; docks brought face to face that the plan did not
-- ask for latch as well, and are in the shape the steps leave (behaviors/reconfigure.lua refuses
-- steps whose shape is not the target). Collisions on the way are not checked: in the lattice a
-- half-turned module passes only sites next to its carrier.
--
-- The executor needs nothing but the link-state map (lua/linkstate.lua): each module takes as the
-- step under way the first one whose result its map does not show yet (a turn: the connection it
-- makes; a release: the connection gone). The carrier of a turn ramps its equator by 180 degrees
-- at M.turn_speed; the mover of a release disables its dock. A turn whose connection has not
-- latched M.latch_timeout seconds after the ramp ends turns back and tries again (M.tries turns in
-- all); then it fails: the carrier says why (module.publish("failed", ...)) and the news floods the
-- robot, every module stopping with the same reason.
local M = {}

M.turn_speed = 0.8     -- rad/s: the equator's target moves this fast (the motor's limit is 1 rad/s)
M.latch_timeout = 3    -- s after a turn's ramp: its connection must have latched by then
M.start_delay = 0.5    -- s after the executor is made: the first step begins
M.tries = 2            -- turns a move gets: the first, and after turning back, one more

-- ===== Geometry (the dock layout of assets/modules/atron.lua) =====

local kRadius, c = 0.055, math.sqrt(0.5)
local kDock = {}
for _, h in ipairs({"n", "s"}) do
  for i = 0, 3 do
    local ca, sa = ({1, 0, -1, 0})[i + 1], ({0, 1, 0, -1})[i + 1]
    local z = h == "n" and 1 or -1
    kDock[h .. i] = {
      at = {kRadius * c * ca, kRadius * c * sa, kRadius * c * z},
      normal = {c * ca, c * sa, c * z},
      up = {-c * ca, -c * sa, c * z},
      male = i % 2 == 0,
    }
  end
end

-- 3 x 3 matrices as rows {a, b, c, d, e, f, g, h, i}.
local function mv(m, v)
  return {m[1] * v[1] + m[2] * v[2] + m[3] * v[3], m[4] * v[1] + m[5] * v[2] + m[6] * v[3],
          m[7] * v[1] + m[8] * v[2] + m[9] * v[3]}
end
local function mm(a, b)
  local r = {}
  for i = 0, 2 do
    for j = 0, 2 do r[3 * i + j + 1] = a[3 * i + 1] * b[j + 1] + a[3 * i + 2] * b[j + 4] + a[3 * i + 3] * b[j + 7] end
  end
  return r
end
local function cross(a, b) return {a[2] * b[3] - a[3] * b[2], a[3] * b[1] - a[1] * b[3], a[1] * b[2] - a[2] * b[1]} end
local function add(a, b) return {a[1] + b[1], a[2] + b[2], a[3] + b[3]} end
local function sub(a, b) return {a[1] - b[1], a[2] - b[2], a[3] - b[3]} end
local function near(a, b, tol) return math.abs(a[1] - b[1]) + math.abs(a[2] - b[2]) + math.abs(a[3] - b[3]) < tol end
-- The rotation with columns x, y, z, and its transpose.
local function cols(x, y, z) return {x[1], y[1], z[1], x[2], y[2], z[2], x[3], y[3], z[3]} end
local function transpose(m) return {m[1], m[4], m[7], m[2], m[5], m[8], m[3], m[6], m[9]} end
-- A half turn about the unit axis a: 2 a a^T - I.
local function halfTurn(a)
  return {2 * a[1] * a[1] - 1, 2 * a[1] * a[2], 2 * a[1] * a[3], 2 * a[2] * a[1], 2 * a[2] * a[2] - 1,
          2 * a[2] * a[3], 2 * a[3] * a[1], 2 * a[3] * a[2], 2 * a[3] * a[3] - 1}
end

-- A module's pose: R (its north hemisphere's orientation), p (centre), and its equator's half
-- turns so far (0 or 1: the south hemisphere turned 180 degrees about the polar axis).
-- Its dock d in the world: {at, normal, up}.
local function dockFrame(pose, d)
  local k = kDock[d]
  local at, n, u = k.at, k.normal, k.up
  if d:sub(1, 1) == "s" and pose.turned == 1 then  -- about z by 180 degrees
    at, n, u = {-at[1], -at[2], at[3]}, {-n[1], -n[2], n[3]}, {-u[1], -u[2], u[3]}
  end
  return {at = add(pose.p, mv(pose.R, at)), normal = mv(pose.R, n), up = mv(pose.R, u)}
end

-- b's pose when its dock db mates a's dock da (world.connect: b's normal opposite, the same up).
local function mate(poseA, da, db, turnedB)
  local fa = dockFrame(poseA, da)
  local own = dockFrame({R = {1, 0, 0, 0, 1, 0, 0, 0, 1}, p = {0, 0, 0}, turned = turnedB}, db)  -- in b's frame
  local n, u = own.normal, own.up
  local N, U = {-fa.normal[1], -fa.normal[2], -fa.normal[3]}, fa.up
  local R = mm(cols(N, U, cross(N, U)), transpose(cols(n, u, cross(n, u))))
  local b = {R = R, turned = turnedB, p = {0, 0, 0}}
  b.p = sub(fa.at, dockFrame(b, db).at)
  return b
end

-- Do docks a.da and b.db face each other, mating as world.connect mates them?
local function facing(poses, a, da, b, db)
  local fa, fb = dockFrame(poses[a], da), dockFrame(poses[b], db)
  return near(fa.at, fb.at, 1e-6) and near(fa.normal, {-fb.normal[1], -fb.normal[2], -fb.normal[3]}, 1e-6) and
         near(fa.up, fb.up, 1e-6)
end

-- ===== Steps =====

local key = require("reconfig").key  -- "a.dock-b.dock", either end first

--- Places every module of shape s (lua/reconfig.lua) from its connections, as world.connect
--- places them with every equator at 0: the first module by name at the origin, each next one
--- where its connection to a placed one puts it. name -> {R = 3 x 3 rotation (rows), p = centre,
--- turned = 0}; or nil and why, for connections that do not close on the lattice.
function M.place(s)
  local poses = {}
  for _, root in ipairs(s.names) do
    if not poses[root] then
      poses[root] = {R = {1, 0, 0, 0, 1, 0, 0, 0, 1}, p = {0, 0, 0}, turned = 0}
      local queue, head = {root}, 1
      while head <= #queue do
        local a = queue[head]
        head = head + 1
        for _, e in ipairs(s.edges) do
          for _, side in ipairs({{e.a, e.da, e.b, e.db}, {e.b, e.db, e.a, e.da}}) do
            local x, dx, y, dy = side[1], side[2], side[3], side[4]
            if x == a then
              local want = mate(poses[a], dx, dy, 0)
              if not poses[y] then
                poses[y] = want
                queue[#queue + 1] = y
              elseif not facing(poses, x, dx, y, dy) then
                return nil, string.format("the connections do not fit the ATRON lattice (%s.%s-%s.%s)", x, dx, y, dy)
              end
            end
          end
        end
      end
    end
  end
  return poses
end

-- The modules that hang on module c's hemisphere h (its docks h0..h3), or nil if one of them also
-- holds c another way (then the hemisphere cannot turn them alone).
local function carried(conns, c, h)
  local set, queue, head = {}, {}, 1
  for _, e in pairs(conns) do
    if e[1] == c and e[2]:sub(1, 1) == h and not set[e[3]] then set[e[3]] = true; queue[#queue + 1] = e[3] end
    if e[3] == c and e[4]:sub(1, 1) == h and not set[e[1]] then set[e[1]] = true; queue[#queue + 1] = e[1] end
  end
  while head <= #queue do
    local x = queue[head]
    head = head + 1
    for _, e in pairs(conns) do
      local y, cd
      if e[1] == x then y, cd = e[3], e[4] elseif e[3] == x then y, cd = e[1], e[2] end
      if y == c then
        -- c again: only through the hemisphere h itself (two of h's docks holding what it carries).
        if cd:sub(1, 1) ~= h then return nil end
      elseif y and not set[y] then
        set[y] = true
        queue[#queue + 1] = y
      end
    end
  end
  return set
end

-- Module c turns hemisphere h by 180 degrees: what hangs on it turns about c's polar axis.
local function turn(poses, c, h, set)
  local pc = poses[c]
  local axis = mv(pc.R, {0, 0, 1})
  local H = halfTurn(axis)
  local function move(pose)
    pose.R = mm(H, pose.R)
    pose.p = add(pc.p, mv(H, sub(pose.p, pc.p)))
  end
  for m in pairs(set) do move(poses[m]) end
  if h == "s" then
    pc.turned = 1 - pc.turned
  else  -- the north hemisphere (the module's frame) turns; the south stays where it was
    move(pc)
    pc.turned = 1 - pc.turned
  end
end

-- Every pair of free docks (one male, one female) that face each other: they latch.
local function latches(s, poses, conns)
  local used, out = {}, {}
  for _, e in pairs(conns) do used[e[1] .. "." .. e[2]] = true; used[e[3] .. "." .. e[4]] = true end
  for i, a in ipairs(s.names) do
    for j = i + 1, #s.names do
      local b = s.names[j]
      local d = sub(poses[a].p, poses[b].p)
      if math.abs(math.sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]) - 2 * kRadius) < 1e-6 then  -- neighbours
        for da, ka in pairs(kDock) do
          for db, kb in pairs(kDock) do
            if ka.male ~= kb.male and not used[a .. "." .. da] and not used[b .. "." .. db] and
               facing(poses, a, da, b, db) then
              out[#out + 1] = {a, da, b, db}
            end
          end
        end
      end
    end
  end
  table.sort(out, function(x, y) return key(x[1], x[2], x[3], x[4]) < key(y[1], y[2], y[3], y[4]) end)
  return out
end

--- The steps that turn shape `now` into `target` (the same modules; lua/reconfig.lua shapes) by
--- half turns and releases, and the shape they leave ({modules =, connections =}, as
--- reconfig.shape takes it): or nil and why.
--- plan: reconfig.plan(now, target) (made here if not given).
function M.compile(now, target, plan)
  for _, shape in ipairs({now, target}) do
    for _, e in ipairs(shape.edges) do
      for _, end_ in ipairs({{e.a, e.da}, {e.b, e.db}}) do
        if not kDock[end_[2]] then
          return nil, string.format("%s.%s: an ATRON has no dock '%s' (n0-n3, s0-s3)", end_[1], end_[2], end_[2])
        end
      end
    end
  end
  plan = plan or require("reconfig").plan(now, target)
  local poses, why = M.place(now)
  if not poses then return nil, why end
  local conns, want = {}, {}
  for _, e in ipairs(now.edges) do conns[key(e.a, e.da, e.b, e.db)] = {e.a, e.da, e.b, e.db} end
  for _, e in ipairs(target.edges) do want[key(e.a, e.da, e.b, e.db)] = true end
  local steps = {}
  for _, o in ipairs(plan.ops) do
    if o.op == "dock" and not conns[key(o[1], o[2], o[3], o[4])] then
      local found
      for _, side in ipairs({{o[1], o[2], o[3], o[4]}, {o[3], o[4], o[1], o[2]}}) do
        local mover, dm, other, dother = side[1], side[2], side[3], side[4]
        local order = {}  -- (in key order: every module must find the same carrier)
        for kk in pairs(conns) do order[#order + 1] = kk end
        table.sort(order)
        for _, kk in ipairs(order) do
          local e = conns[kk]
          for _, hold in ipairs({{e[1], e[2], e[3], e[4]}, {e[3], e[4], e[1], e[2]}}) do
            -- hold: mover.hold[2] is docked to carrier hold[3] at its dock hold[4].
            if not found and hold[1] == mover and hold[3] ~= other then
              local c, h = hold[3], hold[4]:sub(1, 1)
              local set = carried(conns, c, h)
              if set and set[mover] and not set[other] then
                local trial = {}
                for name, p in pairs(poses) do trial[name] = {R = p.R, p = p.p, turned = p.turned} end
                turn(trial, c, h, set)
                if facing(trial, mover, dm, other, dother) then
                  found = {carrier = c, hemisphere = h, mover = mover, poses = trial,
                           release = not want[key(mover, hold[2], c, hold[4])] and {mover, hold[2], c, hold[4]} or nil}
                end
              end
            end
          end
        end
      end
      if not found then
        return nil, string.format("no half turn of a module brings %s.%s to %s.%s", o[1], o[2], o[3], o[4])
      end
      poses = found.poses
      local made = latches(now, poses, conns)
      steps[#steps + 1] = {kind = "turn", owner = found.carrier, hemisphere = found.hemisphere, mover = found.mover,
                           connect = {o[1], o[2], o[3], o[4]}, latches = made}
      for _, l in ipairs(made) do conns[key(l[1], l[2], l[3], l[4])] = l end
      if found.release then
        local r = found.release
        steps[#steps + 1] = {kind = "release", owner = r[1], dock = r[2], from = r[3], from_dock = r[4]}
        conns[key(r[1], r[2], r[3], r[4])] = nil
      end
    end
  end
  -- Connections the target does not have, not yet let go: released last.
  local keys = {}
  for k in pairs(conns) do keys[#keys + 1] = k end
  table.sort(keys)
  for _, k in ipairs(keys) do
    local e = conns[k]
    if not want[k] then
      steps[#steps + 1] = {kind = "release", owner = e[1], dock = e[2], from = e[3], from_dock = e[4]}
      conns[k] = nil
    end
  end
  local built = {}
  for _, k in ipairs(keys) do if conns[k] then built[#built + 1] = conns[k] end end
  return steps, {modules = now.types, connections = built}
end

--- The steps as text, one per line.
function M.format(steps)
  local lines = {}
  for k, s in ipairs(steps) do
    local what
    if s.kind == "turn" then
      local extra = {}
      for _, l in ipairs(s.latches) do
        local kk = key(l[1], l[2], l[3], l[4])
        if kk ~= key(s.connect[1], s.connect[2], s.connect[3], s.connect[4]) then extra[#extra + 1] = kk end
      end
      what = string.format("%s turns its %s hemisphere 180 deg: %s.%s docks to %s.%s%s", s.owner,
                           s.hemisphere == "n" and "north" or "south", s.connect[1], s.connect[2], s.connect[3],
                           s.connect[4], #extra > 0 and (" (and " .. table.concat(extra, ", ") .. ")") or "")
    else
      what = string.format("%s lets go of %s (%s-%s)", s.owner, s.from, s.dock, s.from_dock)
    end
    lines[#lines + 1] = string.format("%2d. %-7s %s", k, s.kind, what)
  end
  return table.concat(lines, "\n")
end

-- ===== The executor =====

local Exec = {}
Exec.__index = Exec

--- Carries `steps` out on this module; `net` is its lua/linkstate.lua endpoint. opts.io.target(joint,
--- rad): how a joint target is set (default module.joint(joint):set_target; behaviors/reconfigure.lua
--- passes its noisy actions).
function M.new(net, steps, opts)
  local io = opts and opts.io or {}
  return setmetatable({net = net, steps = steps, k = 0, at = sim.time() + M.start_delay, done = false,
                       failed = nil, links = {},
                       target = io.target or function(j, rad) module.joint(j):set_target(rad) end}, Exec)
end

-- Is step s's result in the map's links (a set of "name.dock-name.dock")?
local function shows(links, s)
  if s.kind == "turn" then return links[key(s.connect[1], s.connect[2], s.connect[3], s.connect[4])] == true end
  return not links[key(s.owner, s.dock, s.from, s.from_dock)]
end

function Exec:on_dock() end

-- Stops here, says why, and passes the news on over every engaged dock (each module that hears
-- it stops too, and says the same).
local function fail(self, why)
  if self.failed then return end
  self.failed = why
  module.publish("failed", why)
  log("reconfiguration failed: " .. why)
  for i, d in ipairs(self.net.docks) do
    if d:engaged() then self.net:post(i, "moves", {failed = why}) end
  end
end

--- One step of the executor; `parts`: this step's messages (net:receive()).
function Exec:step(parts)
  for _, p in ipairs(parts or {}) do
    local news = p.fields and p.fields.moves
    if type(news) == "table" and news.failed then fail(self, news.failed) end
  end
  if self.done or self.failed then return end
  do  -- (the map as it is now; `changed` is left for the layers that watch it)
    local changed = self.net.changed
    self.map = self.net:map()
    self.net.changed = changed
    self.links = {}
    for _, e in ipairs(self.map.edges) do
      local r = self.map.records
      self.links[key(r[e[1]].name, e[2], r[e[3]].name, e[4])] = true
    end
  end
  if sim.time() < self.at then return end
  local k = 1
  while k <= #self.steps and shows(self.links, self.steps[k]) do k = k + 1 end
  if k > #self.steps then
    if self.turning then self.target("equator", module.joint("equator"):angle()) end
    self.done = true
    return
  end
  local s = self.steps[k]
  if k ~= self.k then  -- a new step under way (as this module's map shows it)
    if self.turning then
      -- The turn latched: the equator holds where the contact stopped it (the faces meet a little
      -- before 180 degrees), instead of pressing on at its rating.
      self.target("equator", module.joint("equator"):angle())
      self.turning = false
    end
    self.k, self.began, self.tries = k, sim.time(), 1
    if s.owner == module.name and s.kind == "turn" then
      self.from = module.joint("equator"):angle()
      self.to = self.from + math.pi
    end
  end
  if s.owner ~= module.name then return end
  if s.kind == "release" then
    module.dock(s.dock):disable()
    return
  end
  -- The turn: out by 180 degrees; if the connection has not latched M.latch_timeout after, back
  -- to where it started and out again, once (M.tries turns in all).
  local ramp = math.pi / M.turn_speed
  local t = sim.time() - self.began
  self.turning = true
  if t <= ramp + M.latch_timeout then
    self.target("equator", self.from + math.min(1, t / ramp) * (self.to - self.from))
  elseif self.tries < M.tries then
    local back = t - ramp - M.latch_timeout
    self.target("equator", self.to + math.min(1, back / ramp) * (self.from - self.to))
    if back >= ramp then
      self.tries, self.began = self.tries + 1, sim.time()
      module.publish("retries", self.tries - 1)
      log(string.format("%s.%s did not latch to %s.%s: turning back and again", s.connect[1], s.connect[2],
                        s.connect[3], s.connect[4]))
    end
  else
    fail(self, string.format("%s.%s did not latch to %s.%s within %.0f s of the turn, %d turns", s.connect[1],
                             s.connect[2], s.connect[3], s.connect[4], M.latch_timeout, M.tries))
  end
end

return M
