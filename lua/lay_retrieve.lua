-- Carrying out a reconfiguration plan on the ground, for chain-type modules (SuperBot). From a
-- snake lying on the ground to a shape made of a chain (its head and body) and one-module legs
-- docked by their front faces to the chain's side docks, and back, with moves that stay inside a
-- SuperBot's torque limits (no joint lifts or drags more than one module). To the legs, "lay and
-- retrieve":
--
-- 1. lay: the snake's last module is swung a quarter turn by its neighbour's yaw joint, so that it
--    lies across the chain's side with its front face looking at the chain; the neighbour lets go
--    of it (a cut) and turns its yaw back (or, if it is itself laid next for the chain's last
--    module, once it is captured). A right leg first, then a left one.
-- 2. retrieve: the rest of the chain crawls backwards (the caterpillar wave run tail first) with
--    only the two side docks that must take the legs enabled, until both have captured and
--    latched their legs.
--
-- Back to a snake, "release and take": a leg lifts its hip and is let go (it tips out, clear of the
-- chain); the tail turns its back bracket towards the leg and the chain crawls forward until that
-- dock takes it; the tail turns back, drawing the leg into line as the new tail. The tail's own
-- legs are let go one at a time, each just before its take (so the first draw-in, which turns the
-- chain a little, turns the second leg with it); legs further up the chain together.
--
-- Socket pairs are served from the front of the chain backwards, so a leg already docked never
-- passes a deposit. Each module computes the same steps from the same committed map and target
-- (lua/agree.lua), and runs them by messages through its docks (lua/linkstate.lua's fields):
--
--   local steps = require("lay_retrieve").compile(now, target)   -- the same on every module
--   local exec = require("lay_retrieve").new(net, steps, {size = modules})
--   function step(dt) local parts = net:receive(); exec:step(parts); net:send() end
--   function on_dock(dock, event) net:on_dock(dock, event); exec:on_dock(dock, event) end
--
-- Each step has an owner, the module that sees it finish: the joint's module for a sweep, the
-- cutting module for a cut, the socket module for a crawl. The owner floods {k = the next step,
-- at = when it starts}; a module that hears of a later step than its own adopts it and passes it
-- on. The start time is far enough ahead for the news to cross the robot, so every module of a
-- crawl starts its wave at the same time, in phase. A deposited module is out of touch until it is
-- captured; it has nothing to do meanwhile, and catches up from the first message it gets.
--
-- Moves made to survive joint errors (docs/self-reconfiguration.md, Noise): a sweep's target
-- moves at M.sweep_speed, and while a yaw sweep drags a module over the ground every module's
-- pitch is limp, so the robot lies on the ground as it is rather than on a few points; a crawl's
-- change of amplitude or direction blends in over M.wave_blend; a socket whose capture stalls
-- lets go and takes again after M.retake_after; the walk's way is measured from averaged
-- positions.
--
-- Physics is checked as it runs: a step not finished in its time (a sweep that cannot reach its
-- angle, a crawl that does not capture), a connection that breaks, or a socket that latches the
-- wrong module stops the run; the module that saw it floods the reason, and every module publishes
-- it (`failed`) and holds its pose.
local gait = require("walker_gait")
local M = {}

local kQuarter = math.pi / 2
local kSettle = 0.1         -- rad: a sweep is done within this of its angle (joint noise, a joint limit)...
local kSettleSpeed = 0.05   -- rad/s: ...and this slow
-- rad: the wave, until a socket senses its leg: 6 modules crawl 6 cm/s backwards (at 0.6, 7.7 cm/s,
-- but a 10-module chain's docks then peak at 74 N instead of 55)
M.crawl_amplitude = 0.5
M.forward_amplitude = 0.4   -- rad: forward, to a leg (at 0.5, a 7-module chain's docks peaked at 69 N)
M.tip_hip = -0.5            -- rad: a leg's hip as it is let go (it tips out 2.2 cm as it flattens)
M.tip_wait = 0.7            -- s: a let-go leg flattens its hip this long after it is free
M.carry_hip = -0.8          -- rad: a docked leg's hip while the chain crawls (its foot off the ground)
M.lost_after = 1.5          -- s: a socket that has sensed its leg and then not for this long has passed it
M.return_time = 12         -- s: after turning round, the socket has this long to sense its leg again
M.max_turns = 6             -- times a crawl turns round to pass its leg again before it fails
-- While a socket senses its leg, a yaw joint bends it sideways until the gap along its normal
-- (the proximity times the bearing's x) is within [0, bend_gap]: the socket module's own yaw,
-- or, for the chain's last module, the yaw of the module ahead (the lighter end swings).
M.bend_gain = 8             -- rad per second per metre of gap outside [0, bend_gap]
M.bend_gap = 0.025          -- m (the capture radius is 3 cm)
M.bend_max = 0.4            -- rad
M.creep_amplitude = 0.2     -- rad: then a lower one, which keeps the socket within capture height (1.8 cm/s)
M.crawl_period = 1.5        -- s
M.walk_readings = 30        -- positions the walk's way is averaged over (0.5 s at dt 1/60)
M.wave_blend = 0.75         -- s: a change of the wave's amplitude or direction blends in over this
M.retake_after = 1.0        -- s: a socket whose capture stalled lets go this long, then takes again
M.sweep_speed = 1.0         -- rad/s: a sweep's target moves at most this fast
M.crawl_lag = -2 * math.pi / 5  -- rad between neighbours: negative runs the wave tail first (backwards)

-- The snake's modules in order from its head (the module whose front dock is free), or nil and why.
local function chainOrder(s)
  local backOf, hasFront = {}, {}
  for _, e in ipairs(s.edges) do
    if e.da == "back" and e.db == "front" then
      backOf[e.a], hasFront[e.b] = e.b, true
    elseif e.da == "front" and e.db == "back" then
      backOf[e.b], hasFront[e.a] = e.a, true
    else
      return nil, "the shape is not a snake: " .. e.a .. "." .. e.da .. " - " .. e.b .. "." .. e.db
    end
  end
  local head
  for _, n in ipairs(s.names) do
    if not hasFront[n] then
      if head then return nil, "the shape is not one snake: " .. head .. " and " .. n .. " both lead" end
      head = n
    end
  end
  local order = {}
  while head do
    order[#order + 1] = head
    head = backOf[head]
  end
  if #order ~= #s.names then return nil, "the shape is not one snake" end
  return order
end

-- The target as a chain and its legs: {chain = names from the head, sockets = {{p = chain index,
-- side = "left"|"right"}}}, or nil and why.
local function legged(t)
  local degree = {}
  for _, n in ipairs(t.names) do degree[n] = 0 end
  for _, e in ipairs(t.edges) do
    degree[e.a], degree[e.b] = degree[e.a] + 1, degree[e.b] + 1
  end
  local chainEdges, legs = {}, {}
  for _, e in ipairs(t.edges) do
    if e.da == "back" and e.db == "front" then
      chainEdges[#chainEdges + 1] = {e.a, e.b}
    elseif e.da == "front" and e.db == "back" then
      chainEdges[#chainEdges + 1] = {e.b, e.a}
    elseif (e.da == "left" or e.da == "right") and e.db == "front" and degree[e.b] == 1 then
      legs[#legs + 1] = {body = e.a, side = e.da, leg = e.b}
    elseif (e.db == "left" or e.db == "right") and e.da == "front" and degree[e.a] == 1 then
      legs[#legs + 1] = {body = e.b, side = e.db, leg = e.a}
    else
      return nil, "lay and retrieve builds a chain with one-module legs on side docks; the target has " ..
             e.a .. "." .. e.da .. " - " .. e.b .. "." .. e.db
    end
  end
  local backOf, hasFront, isLeg = {}, {}, {}
  for _, c in ipairs(chainEdges) do backOf[c[1]], hasFront[c[2]] = c[2], true end
  for _, l in ipairs(legs) do isLeg[l.leg] = true end
  local head
  for _, n in ipairs(t.names) do
    if not isLeg[n] and not hasFront[n] then
      if head then return nil, "the target's chain has two heads: " .. head .. " and " .. n end
      head = n
    end
  end
  local chain, index = {}, {}
  while head do
    chain[#chain + 1] = head
    index[head] = #chain
    head = backOf[head]
  end
  if #chain + #legs ~= #t.names then return nil, "the target is not one chain with legs" end
  local sockets = {}
  for _, l in ipairs(legs) do
    if not index[l.body] then return nil, "leg " .. l.leg .. " is docked to another leg" end
    sockets[#sockets + 1] = {p = index[l.body], side = l.side, leg = l.leg}
  end
  -- Front first; at one body module the right side first (it is laid first).
  table.sort(sockets, function(a, b)
    if a.p ~= b.p then return a.p < b.p end
    return a.side == "right" and b.side == "left"
  end)
  return {chain = chain, sockets = sockets}
end

-- Rounds: the sockets (sorted, front first) grouped by their chain index.
local function roundsOf(sockets)
  local rounds = {}
  for _, x in ipairs(sockets) do
    local r = rounds[#rounds]
    if not r or r.p ~= x.p then
      r = {p = x.p, sockets = {}}
      rounds[#rounds + 1] = r
    end
    r.sockets[#r.sockets + 1] = x
  end
  return rounds
end

-- Lay and retrieve: from the snake `order` (names from its head) to the legged shape `to`.
local function layAndRetrieve(from, order, to, opts)
  local target, why = legged(to)
  if not target then return nil, why end
  local n, c = #order, #target.chain
  if c < 3 then return nil, "the target's chain is shorter than 3 modules: it could not crawl" end
  local rounds = roundsOf(target.sockets)
  local steps, m, conns = {}, n, {}
  for i = 1, c - 1 do conns[#conns + 1] = {order[i], "back", order[i + 1], "front"} end
  for _, r in ipairs(rounds) do
    local sockets = {}
    local onLast = r.p == m - #r.sockets  -- the socket module is the crawling chain's last
    for xi, x in ipairs(r.sockets) do
      local side = x.side
      local leg, mover = order[m], order[m - 1]
      if m <= c then return nil, "the snake has too few modules left to lay a leg for " .. order[r.p] end
      steps[#steps + 1] = {kind = "sweep", owner = mover, joint = "yaw", angle = side == "right" and kQuarter or -kQuarter,
                           leg = leg}
      steps[#steps + 1] = {kind = "cut", owner = mover, dock = "back", leg = leg}
      -- The mover turns its yaw back, unless it is laid next for the chain's last module: turning
      -- back, the corners of its back bracket (6.3 cm from the joint) sweep through the laid leg's
      -- face (5.2 cm) and push the leg 1.8 cm out. Beside the chain's last module that put the leg
      -- beyond its socket's reach: the module ahead bent to its limit and the chain crept past.
      -- Further up the chain the push gives the modules that crawl past the leg room (without it
      -- they rubbed legs up to 35 deg askew). A mover left turned straightens once it is captured.
      if not (onLast and xi < #r.sockets) then
        steps[#steps + 1] = {kind = "sweep", owner = mover, joint = "yaw", angle = 0}
      end
      sockets[#sockets + 1] = {side, leg}
      conns[#conns + 1] = {order[r.p], side, leg, "front"}
      m = m - 1
    end
    local chain = {}
    for i = 1, m do chain[i] = order[i] end
    steps[#steps + 1] = {kind = "crawl", owner = order[r.p], chain = chain, sockets = sockets}
  end
  if m ~= c then return nil, string.format("the snake has %d modules beyond the target's chain and legs", m - c) end
  if opts.walk and opts.walk > 0 then
    -- Walk: the legs trot, diagonal pairs together (lua/walker_gait.lua); the head measures the way.
    local legs = {}
    for j, r in ipairs(rounds) do
      for _, x in ipairs(conns) do
        if x[1] == order[r.p] and (x[2] == "left" or x[2] == "right") then
          local first = (x[2] == "left") == (j % 2 == 1)
          legs[#legs + 1] = {x[3], x[2], first and 0 or 0.5}
        end
      end
    end
    steps[#steps + 1] = {kind = "walk", owner = order[1], distance = opts.walk, legs = legs}
  end
  local mods = {}
  for _, name in ipairs(from.names) do mods[name] = from.types[name] end
  return steps, {modules = mods, connections = conns}
end

--- The steps as text, one a line.
function M.format(steps)
  local lines = {}
  for k, s in ipairs(steps) do
    local what
    if s.kind == "sweep" then
      what = string.format("%s turns %s to %+.0f deg%s", s.owner, s.joint, math.deg(s.angle),
                           s.leg and (" (laying " .. s.leg .. ")") or "")
    elseif s.kind == "cut" then
      what = string.format("%s lets go of %s (%s)", s.owner, s.leg, s.dock)
    elseif s.kind == "walk" then
      local names = {}
      for _, l in ipairs(s.legs) do names[#names + 1] = l[1] end
      what = string.format("%s walk %.2f m forward (%s trot)", s.owner, s.distance, table.concat(names, ", "))
    else
      local got = {}
      for _, x in ipairs(s.sockets) do got[#got + 1] = s.owner .. "." .. x[1] .. " takes " .. x[2] end
      what = string.format("%s..%s crawl %s until %s", s.chain[1], s.chain[#s.chain], s.forward and "forward" or "back",
                           table.concat(got, ", "))
    end
    lines[#lines + 1] = string.format("%2d. %-5s %s", k, s.kind, what)
  end
  return table.concat(lines, "\n")
end

-- From a chain with one-module legs back to a snake (release and take): the legs of the last
-- socket module first. Each leg lifts its hip (M.tip_hip) and is let go: it tips outwards and,
-- once it has flattened its hip again, lies with its front face 2.2 cm out from the chain's side,
-- so the chain passes it without touching. Then, a leg at a time (left first), the tail turns its
-- back bracket a quarter towards the leg's side and the chain crawls forward until that back dock
-- has taken the leg; the tail turns back, drawing the leg into line as the new tail.
local function releaseAndTake(from, order)
  local src, why = legged(from)
  if not src then return nil, why end
  local chain = {}
  for i, name in ipairs(src.chain) do chain[i] = name end
  if #chain < 3 then return nil, "the chain is shorter than 3 modules: it could not crawl" end
  local rounds = roundsOf(src.sockets)
  local steps = {}
  for ri = #rounds, 1, -1 do
    local r = rounds[ri]
    table.sort(r.sockets, function(a, b) return a.side == "left" and b.side == "right" end)
    -- A leg on the tail's sockets is let go just before its take: drawing the leg before it into
    -- line turns the chain a few degrees, and a leg let go earlier lay 3 to 8 cm off the new tail's
    -- way. Further up the chain the legs are let go together, so that one crawl brings the tail to
    -- both.
    local late = r.p == #chain
    local function release(x)
      steps[#steps + 1] = {kind = "sweep", owner = x.leg, joint = "pitch", angle = M.tip_hip}
      steps[#steps + 1] = {kind = "cut", owner = chain[r.p], dock = x.side, leg = x.leg, release = true}
    end
    if not late then
      for _, x in ipairs(r.sockets) do release(x) end
    end
    for _, x in ipairs(r.sockets) do
      if late then release(x) end
      local tail, list = chain[#chain], {}
      for i, name in ipairs(chain) do list[i] = name end
      steps[#steps + 1] = {kind = "sweep", owner = tail, joint = "yaw", angle = x.side == "right" and kQuarter or -kQuarter}
      steps[#steps + 1] = {kind = "crawl", owner = tail, chain = list, sockets = {{"back", x.leg}}, forward = true,
                           side = x.side}
      steps[#steps + 1] = {kind = "sweep", owner = tail, joint = "yaw", angle = 0}
      chain[#chain + 1] = x.leg
    end
  end
  if #chain ~= #order then return nil, "the target snake has other modules than the chain and its legs" end
  local mods, conns = {}, {}
  for _, name in ipairs(from.names) do mods[name] = from.types[name] end
  for i = 1, #chain - 1 do conns[i] = {chain[i], "back", chain[i + 1], "front"} end
  return steps, {modules = mods, connections = conns}
end

--- The steps from `from` to `to` (reconfig shapes of the same modules), and the shape they make;
--- or nil and why. From a snake to a chain with one-module legs on side docks (lay and retrieve;
--- with opts.walk, metres, the walker then trots that far), or back (release and take).
--- Steps: {kind = "sweep", owner = module, joint =, angle =} | {kind = "cut", owner =, dock =}
--- | {kind = "crawl", owner = socket module, chain = names from the head, sockets = {{dock, leg}},
--- forward = true or nil}
--- | {kind = "walk", owner = the head, distance = m, legs = {{name, side, phase}}}.
function M.compile(from, to, opts)
  opts = opts or {}
  local order, why = chainOrder(from)
  if order then return layAndRetrieve(from, order, to, opts) end
  if legged(from) then
    local target, whyTo = chainOrder(to)
    if target then return releaseAndTake(from, target) end
    return nil, "from a chain with one-module legs, steps are made to a snake only: " .. whyTo
  end
  return nil, why .. ", nor a chain with one-module legs on side docks"
end

local Exec = {}
Exec.__index = Exec

-- What the runner senses and commands, unless opts.io gives its own (with noise, say): the
-- percepts "dock:<name>" (the docks' proximity), "heading" (the orientation sensor) and "position"
-- must be declared by the behaviour.
local function defaultIo()
  return {
    target = function(joint, rad) module.joint(joint):set_target(rad) end,
    free = function(joint) module.joint(joint):free() end,
    proximity = function(dock)
      local r = module.sense("dock:" .. dock)
      return r and r.proximity
    end,
    bearing = function(dock)
      local r = module.sense("dock:" .. dock)
      return r and r.bearing
    end,
    heading = function() return gait.heading(module.sense("heading")) end,
    position = function() return module.sense("position") end,
  }
end

--- The runner of `steps` on this module (`net` from lua/linkstate.lua). opts: size (modules in
--- the robot: the news' lead), io ({target(joint, rad), free(joint) (optional: the motor off),
--- proximity(dock), bearing(dock), heading(),
--- position()}),
--- timeouts (sweep_timeout, crawl_timeout, walk_timeout, s).
function M.new(net, steps, opts)
  opts = opts or {}
  local self = setmetatable({
    net = net, steps = steps, name = module.name,
    k = 1, at = sim.time() + (opts.delay or 0.5),  -- the step under way, and when it starts
    began = nil,           -- the step this module last began
    captured = {},         -- dock name -> true: a socket of the current crawl latched its leg
    amp = M.crawl_amplitude, ampFrom = 0, ampBefore = M.crawl_amplitude,  -- the wave's amplitude from a time
    creeping = false,      -- (a crawl's owner) a socket has sensed its leg
    failed = nil, done = false,
    timeout = {sweep = opts.sweep_timeout or 3, cut = 1, crawl = opts.crawl_timeout or 90, walk = opts.walk_timeout or 60},
    hop = sim.dt() * 1.0,
    size = opts.size or 32,  -- modules: the news' lead time is this many hops
    isLeg = false,         -- this module is laid and retrieved as a leg
    io = opts.io or defaultIo(),
  }, Exec)
  for _, s in ipairs(steps) do
    if s.leg == self.name then self.isLeg = true end
  end
  return self
end

-- Posts a field on every engaged dock but `except` (a neighbour whose hello has not arrived yet
-- gets it too: a leg captured this step must hear that the crawl is over).
local function flood(self, field, except)
  for i, d in ipairs(self.net.docks) do
    if i ~= except and d:engaged() then self.net:post(i, "exec", field) end
  end
end

local function fail(self, why)
  if self.failed then return end
  self.failed = why
  module.publish("failed", why)
  log("reconfiguration failed: " .. why)
  flood(self, {fail = why})
end

-- The owner saw step k finish: the next starts after the news has crossed the robot.
local function advance(self)
  self.k = self.k + 1
  self.at = sim.time() + self.size * self.hop
  flood(self, {k = self.k, at = self.at})
end

local function indexOf(list, x)
  for i, v in ipairs(list) do
    if v == x then return i end
  end
  return nil
end

-- Starts step k on this module (once): sets docks and joints for it.
local function begin(self, s)
  self.began = self.k
  self.captured = {}
  local amp = s.forward and M.forward_amplitude or M.crawl_amplitude
  self.amp, self.ampFrom, self.ampBefore, self.creeping = amp, 0, amp, false
  self.dir, self.dirBefore, self.turns, self.lastNear = 1, 1, 0, nil
  self.bendI, self.bendSent, self.bendFor = 0, 0, nil
  self.retake = nil  -- (sockets to enable again, by dock name: a capture stalled)
  self.started = sim.time()
  if s.kind == "sweep" and s.joint == "yaw" then
    -- A yaw sweep drags a module over the ground: every module lets its pitch go limp, so the robot
    -- lies on the ground as it is. (Held at 0 with actuator noise, a chain lay on a few points, the
    -- swung module pressed on the ground and its drag buckled the chain 10 deg at the next yaw ahead.)
    if self.io.free then self.io.free("pitch") else module.joint("pitch"):free() end
  end
  if s.kind == "sweep" and s.owner == self.name then
    self.sweepFrom = module.joint(s.joint):angle()
    self.sweepRamp = math.abs(s.angle - self.sweepFrom) / M.sweep_speed
  elseif s.kind == "sweep" and s.leg == self.name then
    -- About to be laid: only the front dock stays willing (the one a socket will take).
    for _, d in ipairs(module.docks()) do
      if d ~= "front" and not module.dock(d):engaged() then module.dock(d):disable() end
    end
  elseif s.kind == "cut" and s.owner == self.name then
    module.dock(s.dock):disable()
  elseif s.kind == "cut" and s.release and s.leg == self.name then
    -- About to be let go: only the front dock stays willing (the one the tail will take).
    for _, d in ipairs(module.docks()) do
      if not module.dock(d):engaged() then module.dock(d):disable() end
    end
    module.dock("front"):enable()
  elseif s.kind == "walk" then
    self.readings = {n = 0, x = 0, y = 0}
    self.heading0 = nil
  elseif s.kind == "crawl" and indexOf(s.chain, self.name) then
    -- Only the sockets take anything while the chain passes the deposits.
    for _, d in ipairs(module.docks()) do
      local dock = module.dock(d)
      local socket = false
      for _, x in ipairs(s.sockets) do
        if s.owner == self.name and x[1] == d then socket = true end
      end
      if socket then dock:enable() elseif not dock:engaged() then dock:disable() end
    end
  end
end

--- Call from on_dock(dock, event) (after net:on_dock).
function Exec:on_dock(dock, event)
  if self.failed or self.done then return end
  local s = self.steps[self.k]
  if event == "broken" then
    fail(self, string.format("%s.%s broke", self.name, dock:name()))
    return
  end
  if event == "disengaged" and self.isLeg and dock:name() == "front" then
    -- Let go (or laid): out of touch from now on, so it flattens its hip by itself.
    self.flattenAt = sim.time() + M.tip_wait
  end
  if event == "engaged" and self.isLeg and dock:name() == "front" then
    -- Captured: a leg laid with its yaw still turned (the mover of the leg laid before it)
    -- straightens it, its foot in the air.
    self.io.target("yaw", 0)
  end
  if event == "engaged" then
    -- A module just joined (a captured leg): tell it where the run is.
    self.net:post(self.net.index[dock:name()], "exec", {k = self.k, at = self.at})
  end
  if not s or self.began ~= self.k then return end
  if event == "disengaged" and s.kind == "cut" and s.owner == self.name and dock:name() == s.dock then
    advance(self)
  elseif event == "engaged" and s.kind == "crawl" and s.owner == self.name then
    for _, x in ipairs(s.sockets) do
      if x[1] == dock:name() then self.captured[x[1]] = true end
    end
  elseif event == "stalled" and s.kind == "crawl" and s.owner == self.name then
    -- A capture that has not latched in its time (the faces met askew): let go, and take the leg
    -- again once the crawl has moved on a little.
    for _, x in ipairs(s.sockets) do
      if x[1] == dock:name() and not self.captured[x[1]] then
        dock:disable()
        self.retake = self.retake or {}
        self.retake[x[1]] = sim.time() + M.retake_after
        log(string.format("%s stalled taking %s: letting go, taking it again in %.1f s", x[1], x[2], M.retake_after))
      end
    end
  end
end

--- Call once a step with what net:receive() returned (the "exec" fields), before net:send().
function Exec:step(parts)
  for _, p in ipairs(parts) do
    local e = p.fields.exec
    if type(e) == "table" then
      if type(e.fail) == "string" and not self.failed then
        self.failed = e.fail
        module.publish("failed", e.fail)
        flood(self, {fail = e.fail}, p.dock)
      elseif type(e.k) == "number" and type(e.at) == "number" and e.k > self.k then
        self.k, self.at = e.k, e.at
        flood(self, {k = e.k, at = e.at}, p.dock)
      elseif type(e.bend) == "number" and e.step == self.k then
        -- The socket behind asks this module to bend it towards its leg.
        self.io.target("yaw", math.max(-M.bend_max, math.min(M.bend_max, e.bend)))
        self.bent = true
      elseif type(e.amp) == "number" and type(e.from) == "number" and e.step == self.k and e.from ~= self.ampFrom then
        self.ampBefore, self.amp, self.ampFrom = self.amp, e.amp, e.from
        self.dirBefore, self.dir = self.dir, e.dir == -1 and -1 or 1
        flood(self, {step = e.step, amp = e.amp, dir = self.dir, from = e.from}, p.dock)
      end
    end
  end
  if self.failed or self.done then return end
  local t = sim.time()
  local s = self.steps[self.k]
  -- A crawl that has ended for this module: lie flat.
  if self.wasCrawling and (not s or s.kind ~= "crawl" or t < self.at) then
    self.io.target("pitch", 0)
    self.wasCrawling = false
    if self.bent then
      self.io.target("yaw", 0)  -- straight again
      self.bent = false
    end
  end
  if self.walking and (not s or s.kind ~= "walk" or t < self.at) then
    -- Lie down: the hip and the foot straight.
    self.io.target("pitch", 0)
    self.io.target("yaw", 0)
    self.walking = false
  end
  if self.flattenAt and t >= self.flattenAt then
    self.io.target("pitch", 0)
    self.flattenAt = nil
  end
  if self.k > #self.steps then
    self.done = true
    module.publish("reconfigured", sim.time())
    return
  end
  if t < self.at then return end
  if self.began ~= self.k then begin(self, s) end
  if s.kind == "sweep" and s.owner == self.name then
    local j = module.joint(s.joint)
    if self.sweepFrom then
      local f = self.sweepRamp > 0 and math.min(1, (t - self.started) / self.sweepRamp) or 1
      self.io.target(s.joint, self.sweepFrom + f * (s.angle - self.sweepFrom))
      if f >= 1 then self.sweepFrom = nil end
    end
    if not self.sweepFrom and math.abs(j:angle() - s.angle) < kSettle and math.abs(j:velocity()) < kSettleSpeed then
      advance(self)
    elseif t - self.started > self.sweepRamp + self.timeout.sweep then
      fail(self, string.format("step %d: %s's %s did not reach %+.0f deg in %.0f s (at %+.1f deg)", self.k,
                               self.name, s.joint, math.deg(s.angle), self.sweepRamp + self.timeout.sweep,
                               math.deg(j:angle())))
    end
  elseif s.kind == "cut" and s.owner == self.name then
    if t - self.started > self.timeout.cut then
      fail(self, string.format("step %d: %s could not let go of its %s dock", self.k, self.name, s.dock))
    end
  elseif s.kind == "walk" then
    for _, l in ipairs(s.legs) do
      if l[1] == self.name then
        local h = self.io.heading()
        self.heading0 = self.heading0 or h
        local pitch, yaw = gait.leg(t - self.at, l[2], l[3], gait.wrap(h - self.heading0))
        self.io.target("pitch", pitch)
        self.io.target("yaw", yaw)
        self.walking = true
      end
    end
    if s.owner == self.name then
      -- The way walked, from the mean of the last M.walk_readings positions (one reading, with
      -- 5 mm of noise on each, stopped the walker 2 cm short).
      local p, r = self.io.position(), self.readings
      r.n = r.n + 1
      local slot = (r.n - 1) % M.walk_readings + 1
      r.x, r.y = r.x + p[1] - (r[2 * slot - 1] or 0), r.y + p[2] - (r[2 * slot] or 0)
      r[2 * slot - 1], r[2 * slot] = p[1], p[2]
      local m = math.min(r.n, M.walk_readings)
      if r.n <= M.walk_readings then self.from = {r.x / m, r.y / m} end  -- (the start, averaged too)
      local d = math.sqrt((r.x / m - self.from[1]) ^ 2 + (r.y / m - self.from[2]) ^ 2)
      if d >= s.distance then
        log(string.format("walked %.3f m in %.1f s", d, t - self.at))
        advance(self)
      elseif t - self.started > self.timeout.walk then
        fail(self, string.format("step %d: walked only %.3f m of %.2f in %.0f s", self.k, d, s.distance,
                                 self.timeout.walk))
      end
    end
  elseif s.kind == "crawl" then
    local i = indexOf(s.chain, self.name)
    if self.isLeg and not i and module.dock("front"):engaged() then
      -- A leg already docked rides along lifted (its hip up), not dragged through the crawl.
      self.io.target("pitch", M.carry_hip)
      self.wasCrawling = true
    end
    if i then
      self.wasCrawling = true
      -- (From the wave before to the new one over M.wave_blend s: a jump in every joint's target
      -- at once loaded the docks 50-75 N.)
      local lag = (s.forward and -M.crawl_lag or M.crawl_lag) * (i - 1)
      local phase = 2 * math.pi * (t - self.at) / M.crawl_period
      local w = math.max(0, math.min(1, (t - self.ampFrom) / M.wave_blend))
      local a = w * self.amp * math.sin(phase + lag * self.dir)
      if w < 1 then a = a + (1 - w) * self.ampBefore * math.sin(phase + lag * self.dirBefore) end
      self.io.target("pitch", a)
    end
    if s.owner == self.name then
      for d, at in pairs(self.retake or {}) do
        if t >= at then
          module.dock(d):enable()
          self.retake[d] = nil
        end
      end
      local all = true
      for _, x in ipairs(s.sockets) do
        local d = module.dock(x[1])
        if not self.captured[x[1]] then all = false end
        if d:engaged() then
          local peer = d:peer()
          if self.net.db[peer] and self.net.db[peer].name ~= x[2] then
            fail(self, string.format("step %d: %s.%s took %s, not %s", self.k, self.name, x[1],
                                     self.net.db[peer].name, x[2]))
            return
          end
        end
      end
      -- Creep once a socket still free senses its leg (an IR-style proximity within 0.1 m), until
      -- it has it; the news reaches the whole chain before the wave changes.
      -- (From the second step on: the docks the chain disabled at its first are read the step after.)
      local near
      for _, x in ipairs(t > self.at + 1.5 * self.hop and s.sockets or {}) do
        if not self.captured[x[1]] and self.io.proximity(x[1]) then near = x[1] end
      end
      local creep = near ~= nil or (self.creeping and not self.captured[self.creepFor or ""])
      if near and not self.creeping then self.creepFor = near end
      -- Steer the sensing socket to its leg by the bearing (the IR receivers around its face).
      local sock = self.creepFor
      local b = creep and sock and not self.captured[sock] and self.io.bearing and self.io.bearing(sock)
      local prox = b and self.io.proximity(sock)
      if b and prox then
        local gap = prox * b[1]
        if self.bendFor ~= sock then self.bendI, self.bendFor = 0, sock end
        local err = gap > M.bend_gap and gap - M.bend_gap or (gap < 0 and gap or 0)
        self.bendI = math.max(-M.bend_max, math.min(M.bend_max, self.bendI + M.bend_gain * err * sim.dt()))
        local last = s.chain[#s.chain] == self.name
        local side = sock == "back" and s.side or sock
        -- (a positive yaw turns what lies behind the joint to the right)
        local angle = ((side == "right") == last and 1 or -1) * self.bendI
        if math.abs(angle - self.bendSent) > 0.01 then
          self.bendSent = angle
          if last then
            self.net:post(self.net.index.front, "exec", {step = self.k, bend = angle})
          else
            self.io.target("yaw", angle)
            self.bent = true
          end
        end
      end
      local amp, dir = self.amp, self.dir
      if creep ~= self.creeping then
        self.creeping = creep
        log(creep and (self.creepFor .. " senses its leg: creeping") or (self.creepFor .. " has its leg: crawling"))
        amp, dir = creep and M.creep_amplitude or (s.forward and M.forward_amplitude or M.crawl_amplitude), 1
        self.lastNear, self.seenSinceTurn = t, true
      elseif creep and self.io.proximity(self.creepFor) then
        self.lastNear, self.seenSinceTurn = t, true
      elseif creep and t >= self.ampFrom and
          t - self.lastNear > (self.seenSinceTurn and M.lost_after or M.return_time) then
        -- Sensed, then lost while creeping: the socket has passed its leg. Turn the wave round and
        -- pass it again (a retry), at most M.max_turns times.
        self.turns = self.turns + 1
        if self.turns > M.max_turns then
          fail(self, string.format("step %d: %s.%s passed its leg %d times without taking it", self.k, self.name,
                                   self.creepFor, self.turns))
          return
        end
        log(string.format("%s passed its leg: turning the wave round (%d)", self.creepFor, self.turns))
        dir, self.lastNear, self.seenSinceTurn = -self.dir, t, false
      end
      if amp ~= self.amp or dir ~= self.dir then
        local from = t + self.size * self.hop
        self.ampBefore, self.amp, self.ampFrom = self.amp, amp, from
        self.dirBefore, self.dir = self.dir, dir
        flood(self, {step = self.k, amp = amp, dir = dir, from = from})
      end
      if all then
        advance(self)
      elseif t - self.started > self.timeout.crawl then
        fail(self, string.format("step %d: the crawl did not bring %s's sockets to their legs in %.0f s",
                                 self.k, self.name, self.timeout.crawl))
      end
    end
  end
end

return M
