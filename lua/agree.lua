-- Agreement on the map, for behaviours on lua/linkstate.lua: the modules of a connected part
-- confirm, through dock messages only, that every one of them holds the same map, and then
-- commit to it together. Anything computed from a committed map by a deterministic function (a
-- reconfiguration plan: lua/reconfig.lua) is the same on every module, with no further messages.
--
--   local net = require("linkstate").new()
--   local agreement = require("agree").new(net)
--   function step(dt)
--     agreement:step(net:receive())   -- handles the "agree" fields; posts its own
--     net:send()
--     if agreement.committed then ... agreement.map, agreement.digest ... end
--   end
--
-- The protocol is an echo wave (Chang 1982) started by a leader:
--
-- 1. The leader is the module with the smallest id in its map. Once its map has not changed for
--    `quiet` steps (default: the number of modules in it + 2, more than the map's diameter), it
--    sends a probe {wave, digest of its map} on every link.
-- 2. A module that gets a probe of a new wave takes the dock it came on as its parent, passes the
--    probe on over every other link, and waits for an answer on each: an echo, or the same probe
--    (a link across the tree). It then echoes to its parent whether its map's digest and every
--    answer's agreed. A module with no other links echoes at once.
-- 3. When the leader has every answer: all agreed, it floods a commit {wave, digest} and every
--    module commits to its map; otherwise it waits `quiet` steps again and starts a new wave.
--    A wave not answered within `timeout` steps (default 4 x quiet + 10) is started again.
--
-- A module whose map changes drops the wave it is in, and takes probes only from a leader in its
-- map, so a wave that was about an older map (or from a module no longer connected) cannot hold
-- up the next.
--
-- Messages: one probe and one answer over each link a wave, and one commit over each link, in the
-- same per-dock messages as the link-state records. A committed module ignores later waves (its
-- map may change as the plan runs) until `reset()`.
local linkstate = require("linkstate")

local M = {}
local Agree = {}
Agree.__index = Agree

--- An agreement on `net`'s map. opts: quiet (steps), timeout (steps).
function M.new(net, opts)
  opts = opts or {}
  return setmetatable({
    net = net, opts = opts,
    steps = 0,             -- steps so far
    stable_since = 0,      -- the step the map last changed
    map = nil, digest = nil,
    wave = nil,            -- {leader =, n =}: the wave this module is in
    parent = nil,          -- dock index the wave's probe came on (nil: this module leads it)
    pending = {},          -- dock index -> true: answer awaited
    ok = true,             -- every answer so far agreed
    echoed = false,        -- this module has answered its parent
    started_at = 0,        -- (leader) the step its wave began
    waves = 0,             -- (leader) waves started
    committed = false,
  }, Agree)
end

-- A wave as it arrives in a message: {leader = id, n = count}, or nil for anything else.
local function wave(w)
  if type(w) == "table" and type(w.leader) == "number" and type(w.n) == "number" then return w end
  return nil
end

local function sameWave(a, b)
  return a and b and a.leader == b.leader and a.n == b.n
end

-- A wave is newer than another: a smaller leader, or the same leader's later wave.
local function newer(a, b)
  if not b then return true end
  if a.leader ~= b.leader then return a.leader < b.leader end
  return a.n > b.n
end

local function inMap(map, id)
  for _, m in ipairs(map.members) do
    if m == id then return true end
  end
  return false
end

local function finish(self)
  local net = self.net
  if self.parent then
    if not self.echoed then
      net:post(self.parent, "agree", {echo = self.wave, ok = self.ok})
      self.echoed = true
    end
  elseif self.ok then
    -- The leader: everyone agreed. Commit here, and flood the commit.
    self.committed = true
    for _, i in ipairs(net:links()) do net:post(i, "agree", {commit = self.wave, digest = self.digest}) end
  else
    -- Someone's map differed: wait for quiet again.
    self.wave, self.stable_since = nil, self.steps
  end
end

local function probe(self, wave, digest, parent)
  local net = self.net
  self.wave, self.parent, self.pending, self.echoed = wave, parent, {}, false
  self.ok = (digest == self.digest)
  for _, i in ipairs(net:links()) do
    if i ~= parent then
      self.pending[i] = true
      net:post(i, "agree", {probe = wave, digest = digest})
    end
  end
  if next(self.pending) == nil then finish(self) end
end

local function answered(self, i, ok)
  if not self.pending[i] then return end
  self.pending[i] = nil
  self.ok = self.ok and ok
  if next(self.pending) == nil then finish(self) end
end

--- Call once a step with what net:receive() returned, before net:send().
function Agree:step(parts)
  local net = self.net
  self.steps = self.steps + 1
  if net.changed then
    self.map = net:map()
    local d = linkstate.digest(self.map)
    if d ~= self.digest then
      -- A wave under way was about another map: it cannot succeed here. Drop it (its leader, if
      -- still in the map, will time out and ask again).
      self.digest, self.stable_since = d, self.steps
      if not self.committed then self.wave = nil end
    end
  end
  if self.committed then return end
  for _, p in ipairs(parts) do
    local a = p.fields.agree
    if type(a) == "table" then
      if wave(a.probe) then
        if sameWave(a.probe, self.wave) then
          answered(self, p.dock, true)  -- a link across the tree: the sender answers through its own parent
        elseif newer(a.probe, self.wave) and self.map and inMap(self.map, a.probe.leader) then
          probe(self, {leader = a.probe.leader, n = a.probe.n}, a.digest, p.dock)
        end
      elseif wave(a.echo) then
        if sameWave(a.echo, self.wave) then answered(self, p.dock, a.ok == true) end
      elseif wave(a.commit) then
        if sameWave(a.commit, self.wave) and a.digest == self.digest and not self.committed then
          self.committed = true
          for _, i in ipairs(net:links()) do
            if i ~= p.dock then net:post(i, "agree", {commit = a.commit, digest = a.digest}) end
          end
          return
        end
      end
    end
  end
  -- The leader starts a wave once its map has been quiet, or again when one was not answered.
  local map = self.map
  if map and map.members[1] == net.me then
    local quiet = self.opts.quiet or (#map.members + 2)
    local timeout = self.opts.timeout or (4 * quiet + 10)
    local leading = self.wave and self.wave.leader == net.me
    if (not leading and self.steps - self.stable_since >= quiet) or
        (leading and self.steps - self.started_at >= timeout) then
      self.waves = self.waves + 1
      self.started_at = self.steps
      probe(self, {leader = net.me, n = self.waves}, self.digest, nil)
    end
  end
end

--- Forgets the commit (to agree on a new map: a re-plan).
function Agree:reset()
  self.committed, self.wave, self.stable_since = false, nil, self.steps
end

return M
