-- Link-state discovery over docks, as a library for behaviours: every module learns who is docked
-- to whom, by which docks, and each module's name and type, using nothing but dock messages (one
-- hop per step), the way link-state routing floods a network. It also carries other layers'
-- fields in the same messages, one message per dock per step.
--
--   local linkstate = require("linkstate")
--   local net = linkstate.new()
--   function init() net:init() end
--   function on_dock(dock, event) net:on_dock(dock, event) end
--   function step(dt)
--     for _, m in ipairs(net:receive()) do ... end   -- other layers' fields: m.dock, m.from, m.fields
--     net:post(1, "hello", 42)                       -- a field for dock 1's next message
--     net:send()                                     -- at most one message per dock
--     if net.changed then local map = net:map() ... end
--   end
--
-- What a module knows by itself: its own id, name and type, and which of its docks are engaged.
-- Everything else comes in messages. Every message carries `via` = {sender id, the dock it was
-- sent from}, so the first message over a connection (a hello) tells each side who is at the
-- other end and by which dock.
--
-- Each module keeps one link-state record per module it has heard of: {origin = id, name =,
-- type =, seq = n, links = {{dock, peer, peer_dock}, ...}}. When its own neighbourhood changes (a
-- hello from a new neighbour, a dock that disengages or breaks) it makes a new record with seq + 1
-- and floods it. A record newer than the one held is stored and passed on over every other engaged
-- dock in the next message; older or equal ones are dropped, so each record crosses each
-- connection at most once. A module that meets a new neighbour sends it its whole database.
--
-- The map: a link counts when both ends' records list it (a stale record of a module that has
-- left cannot keep a connection alive), and the map is every such link among the modules
-- reachable from this one through counted links. Message loss (world.channel) is not repaired:
-- a lost record stays lost until its origin's neighbourhood changes again.
local M = {}
local Net = {}
Net.__index = Net

--- A network endpoint for this module (reads the `module` global's docks and identity).
function M.new()
  local names = module.docks()
  local net = {
    names = names, docks = {}, index = {},
    me = module.id, name = module.name, type = module.type,
    db = {},          -- origin id -> record
    neighbours = {},  -- dock name -> {peer = id, dock = name} learned from hellos
    outgoing = {},    -- dock index -> array of records to send this step
    fields = {},      -- dock index -> {key = value} of other layers for this step's message
    hello = {},       -- dock index -> true: send a message (at least the via) this step
    seq = 0,
    changed = true,   -- the map may have changed since the last call of map()
    sent = 0,         -- messages sent so far
    received = 0,     -- messages received so far
  }
  for i, n in ipairs(names) do
    net.docks[i], net.index[n] = module.dock(n), i
  end
  return setmetatable(net, Net)
end

local function queue(net, i, rec)
  local q = net.outgoing[i]
  if not q then
    q = {}
    net.outgoing[i] = q
  end
  q[#q + 1] = rec
end

-- Queues a record for every engaged dock but `except` (a dock index).
local function flood(net, rec, except)
  for i, d in ipairs(net.docks) do
    if i ~= except and d:engaged() then queue(net, i, rec) end
  end
end

-- Queues the whole database for dock i, in origin order (the same messages whatever the table's order).
local function sendAll(net, i)
  local ids = {}
  for id in pairs(net.db) do ids[#ids + 1] = id end
  table.sort(ids)
  for _, id in ipairs(ids) do queue(net, i, net.db[id]) end
end

-- A fresh record of this module's own links, stored and flooded.
local function announce(net)
  net.seq = net.seq + 1
  local links = {}
  for _, n in ipairs(net.names) do
    local nb = net.neighbours[n]
    if nb then links[#links + 1] = {n, nb.peer, nb.dock} end
  end
  local rec = {origin = net.me, name = net.name, type = net.type, seq = net.seq, links = links}
  net.db[net.me] = rec
  flood(net, rec, nil)
  net.changed = true
end

-- Stores a record if it is newer than the one held; true when it was.
local function learn(net, rec)
  if type(rec) ~= "table" or type(rec.origin) ~= "number" or type(rec.seq) ~= "number" or
      type(rec.links) ~= "table" then
    return false
  end
  for _, l in ipairs(rec.links) do  -- (another behaviour's messages on the same docks are not records)
    if type(l) ~= "table" or type(l[1]) ~= "string" or type(l[2]) ~= "number" or type(l[3]) ~= "string" then
      return false
    end
  end
  local old = net.db[rec.origin]
  if rec.origin == net.me or (old and old.seq >= rec.seq) then return false end
  net.db[rec.origin] = rec
  net.changed = true
  return true
end

--- Call from init(): says hello on every engaged dock and makes the first record.
function Net:init()
  for i, d in ipairs(self.docks) do
    if d:engaged() then self.hello[i] = true end
  end
  announce(self)
end

--- Call from on_dock(dock, event).
function Net:on_dock(dock, event)
  local n = dock:name()
  if event == "engaged" then
    -- Say hello and hand over everything known: the other side may be a whole new part.
    local i = self.index[n]
    self.hello[i] = true
    sendAll(self, i)
  elseif self.neighbours[n] then
    self.neighbours[n] = nil
    announce(self)
  end
end

--- Reads every pending message. Handles the link-state part; returns the other layers' parts, in
--- arrival order: {dock = index, dock_name =, from = sender id, from_dock = its dock, fields = {...}}
--- for every message that carried fields.
function Net:receive()
  local out, changed = {}, false
  while true do
    local msg = module.receive()
    if not msg then break end
    self.received = self.received + 1
    local m = msg.data
    local i = self.index[msg.dock]
    if type(m) == "table" and type(m.via) == "table" and type(m.via[1]) == "number" and
        type(m.via[2]) == "string" and i then
      local nb = self.neighbours[msg.dock]
      if not nb or nb.peer ~= m.via[1] or nb.dock ~= m.via[2] then
        self.neighbours[msg.dock] = {peer = m.via[1], dock = m.via[2]}
        changed = true
        -- A new neighbour gets the whole database (its own record comes back to it, and is dropped).
        sendAll(self, i)
      end
      for _, rec in ipairs(type(m.records) == "table" and m.records or {}) do
        if learn(self, rec) then flood(self, rec, i) end
      end
      if type(m.fields) == "table" then
        out[#out + 1] = {dock = i, dock_name = msg.dock, from = m.via[1], from_dock = m.via[2], fields = m.fields}
      end
    end
  end
  if changed then announce(self) end
  return out
end

--- Adds a field to the next message on dock i (an index into module.docks()).
function Net:post(i, key, value)
  local f = self.fields[i]
  if not f then
    f = {}
    self.fields[i] = f
  end
  f[key] = value
end

--- The dock indices whose neighbour is known (engaged, and its hello heard), in dock order.
function Net:links()
  local out = {}
  for i, n in ipairs(self.names) do
    if self.neighbours[n] and self.docks[i]:engaged() then out[#out + 1] = i end
  end
  return out
end

--- Sends this step's messages: at most one per dock, holding the records, the fields posted and
--- the `via`. Returns how many were sent.
function Net:send()
  local n = 0
  for i, d in ipairs(self.docks) do
    if (self.outgoing[i] or self.hello[i] or self.fields[i]) and d:engaged() then
      if d:send({via = {self.me, self.names[i]}, records = self.outgoing[i] or {}, fields = self.fields[i]}) then
        n = n + 1
      end
    end
    self.outgoing[i], self.hello[i], self.fields[i] = nil, nil, nil
  end
  self.sent = self.sent + n
  return n
end

local function key(a, da, b, db)
  if a > b or (a == b and da > db) then a, da, b, db = b, db, a, da end
  return string.format("%d.%s-%d.%s", a, da, b, db)
end

-- True when the record of `peer` lists the link back to (id, dock) by peer_dock.
local function confirms(db, peer, peer_dock, id, dock)
  local rec = db[peer]
  if not rec then return false end
  for _, l in ipairs(rec.links) do
    if l[1] == peer_dock and l[2] == id and l[3] == dock then return true end
  end
  return false
end

--- The map now: {links = sorted "a.dock-b.dock" keys (ids, a < b), edges = {{a, da, b, db}} in the
--- same order, members = sorted ids reachable from this module, records = id -> record}. Clears
--- `changed`.
function Net:map()
  self.changed = false
  local db = self.db
  local seen, ids, set, keys, edges = {[self.me] = true}, {self.me}, {}, {}, {}
  local head = 1
  while head <= #ids do
    local id = ids[head]
    head = head + 1
    local rec = db[id]
    for _, l in ipairs(rec and rec.links or {}) do
      if confirms(db, l[2], l[3], id, l[1]) then
        local k = key(id, l[1], l[2], l[3])
        if not set[k] then
          set[k] = true
          keys[#keys + 1] = k
          if id < l[2] or (id == l[2] and l[1] < l[3]) then
            edges[k] = {id, l[1], l[2], l[3]}
          else
            edges[k] = {l[2], l[3], id, l[1]}
          end
        end
        if not seen[l[2]] then
          seen[l[2]] = true
          ids[#ids + 1] = l[2]
        end
      end
    end
  end
  table.sort(keys)
  table.sort(ids)
  local list = {}
  for i, k in ipairs(keys) do list[i] = edges[k] end
  return {links = keys, edges = list, members = ids, records = db}
end

--- A short digest of a map (32-bit FNV-1a over its members' names and types and its links, as
--- hex): equal maps give equal digests on every module.
function M.digest(map)
  local parts = {}
  for _, id in ipairs(map.members) do
    local r = map.records[id]
    parts[#parts + 1] = id .. "=" .. tostring(r and r.name) .. ":" .. tostring(r and r.type)
  end
  for _, k in ipairs(map.links) do parts[#parts + 1] = k end
  local s, h = table.concat(parts, ";"), 2166136261
  for i = 1, #s do
    h = ((h ~ s:byte(i)) * 16777619) & 0xffffffff
  end
  return string.format("%08x", h)
end

return M
