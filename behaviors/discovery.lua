-- Distributed discovery of the configuration (worlds/discovery.lua): every module learns who is
-- docked to whom, by which docks, using nothing but dock messages (one hop per step), the way
-- link-state routing floods a network.
--
-- What a module knows by itself: its own id and which of its docks are engaged. Everything else
-- comes in messages. Every message a module sends on a dock carries `via` = {sender id, the
-- dock it was sent from}, so the first message over a connection (a hello) tells each side who
-- is at the other end and by which dock.
--
-- Each module keeps a database of link-state records, one per module it has heard of:
-- {origin = id, seq = n, links = {{dock, peer, peer_dock}, ...}}. When its own neighbourhood
-- changes (a hello from a new neighbour, a dock that disengages or breaks) it makes a new record
-- with seq + 1 and floods it. A record newer than the one held (higher seq) is stored and passed
-- on over every other engaged dock in the next message; older or equal ones are dropped, so each
-- record crosses each connection at most once. A module that meets a new neighbour sends it its
-- whole database. All records learned in a step leave in one message per dock.
--
-- The map. A link counts when both ends' records list it (so a stale record of a module that
-- has left cannot keep a connection alive), and the map is every such link among the modules
-- reachable from this one through counted links. It is published (module.publish("map", ...))
-- as a sorted array of "a.dock-b.dock" strings (a < b), for the world to check against
-- world.graph(), and as the number of modules reachable (module.publish("size", n)).
--
-- params:
--   leave_at    seconds: at this time the module disables `leave_dock` (it undocks there)
--   leave_dock  the dock to let go (default "back")
local names = module.docks()
local docks, index = {}, {} -- by index; dock name -> index
for i, n in ipairs(names) do
  docks[i], index[n] = module.dock(n), i
end
local me = module.id

local db = {}          -- origin id -> record
local neighbours = {}  -- dock name -> {peer = id, dock = name} learned from hellos
local outgoing = {}    -- dock index -> array of records to send this step
local hello = {}       -- dock index -> true: send a message (at least the via) this step
local seq = 0
local dirty = true     -- the map may have changed: recompute and publish
local left = false

local function queue(i, rec)
  local q = outgoing[i]
  if not q then
    q = {}
    outgoing[i] = q
  end
  q[#q + 1] = rec
end

--- Queues a record for every engaged dock but `except` (a dock index).
local function flood(rec, except)
  for i, d in ipairs(docks) do
    if i ~= except and d:engaged() then queue(i, rec) end
  end
end

--- A fresh record of this module's own links, stored and flooded.
local function announce()
  seq = seq + 1
  local links = {}
  for _, n in ipairs(names) do
    local nb = neighbours[n]
    if nb then links[#links + 1] = {n, nb.peer, nb.dock} end
  end
  local rec = {origin = me, seq = seq, links = links}
  db[me] = rec
  flood(rec, nil)
  dirty = true
end

--- Stores a record if it is newer than the one held; returns true when it was.
local function learn(rec)
  local old = db[rec.origin]
  if rec.origin == me or (old and old.seq >= rec.seq) then return false end
  db[rec.origin] = rec
  dirty = true
  return true
end

local function key(a, da, b, db_)
  if a > b or (a == b and da > db_) then a, da, b, db_ = b, db_, a, da end
  return string.format("%d.%s-%d.%s", a, da, b, db_)
end

--- True when the record of `peer` lists the link back to (id, dock) by peer_dock.
local function confirms(peer, peer_dock, id, dock)
  local rec = db[peer]
  if not rec then return false end
  for _, l in ipairs(rec.links) do
    if l[1] == peer_dock and l[2] == id and l[3] == dock then return true end
  end
  return false
end

local function publishMap()
  local seen, queueIds, map, set = {[me] = true}, {me}, {}, {}
  local head = 1
  while head <= #queueIds do
    local id = queueIds[head]
    head = head + 1
    local rec = db[id]
    for _, l in ipairs(rec and rec.links or {}) do
      if confirms(l[2], l[3], id, l[1]) then
        local k = key(id, l[1], l[2], l[3])
        if not set[k] then
          set[k] = true
          map[#map + 1] = k
        end
        if not seen[l[2]] then
          seen[l[2]] = true
          queueIds[#queueIds + 1] = l[2]
        end
      end
    end
  end
  table.sort(map)
  module.publish("map", map)
  module.publish("size", #queueIds)
end

function on_dock(dock, event)
  local n = dock:name()
  if event == "engaged" then
    -- Say hello and hand over everything known: the other side may be a whole new part.
    local i = index[n]
    hello[i] = true
    for _, rec in pairs(db) do queue(i, rec) end
  elseif neighbours[n] then
    neighbours[n] = nil
    announce()
  end
end

function init()
  for i, d in ipairs(docks) do
    if d:engaged() then hello[i] = true end
  end
  announce()
end

--- One message: who is at the other end of its dock, and the records it carries. Returns true
--- when the neighbour there is new (this module's own links changed).
local function handle(msg)
  local m = msg.data
  if type(m) ~= "table" or type(m.via) ~= "table" or type(m.records) ~= "table" then return false end
  local i = index[msg.dock]
  local nb, changed = neighbours[msg.dock], false
  if not nb or nb.peer ~= m.via[1] or nb.dock ~= m.via[2] then
    neighbours[msg.dock] = {peer = m.via[1], dock = m.via[2]}
    changed = true
    -- A new neighbour gets the whole database (its own record comes back to it, and is dropped).
    for _, rec in pairs(db) do queue(i, rec) end
  end
  for _, rec in ipairs(m.records) do
    if learn(rec) then flood(rec, i) end
  end
  return changed
end

function step(dt)
  if params.leave_at and not left and sim.time() >= params.leave_at then
    left = true
    module.dock(params.leave_dock or "back"):disable()
    log("undocking " .. (params.leave_dock or "back"))
  end

  local changed = false
  while true do
    local msg = module.receive()
    if not msg then break end
    changed = handle(msg) or changed
  end
  if changed then announce() end

  for i, d in ipairs(docks) do
    if (outgoing[i] or hello[i]) and d:engaged() then
      d:send({via = {me, names[i]}, records = outgoing[i] or {}})
    end
    outgoing[i], hello[i] = nil, nil
  end

  if dirty then
    publishMap()
    dirty = false
  end
end
