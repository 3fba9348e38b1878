-- Distributed discovery: ten SuperBots docked into a tree on the ground (a spine of four with
-- branches off its left, right, front and back docks) learn the whole configuration, who is
-- docked to whom by which docks, only from dock messages, one hop per step
-- (behaviors/discovery.lua floods link-state records with sequence numbers). After every step the
-- world compares each module's published map (module.publish / m:published) with world.graph():
-- every module's map must equal the connections of its own connected component. At 1 s the
-- module `b3` undocks from the spine (it disables its back dock), taking `b4` with it; the maps
-- must then follow: the eight left behind drop the two, and the two know only each other.
--
-- Checks: all maps right within (diameter + 3) steps of the start and of the undocking (the
-- diameter, in hops, is measured on the graph), and still right at the end.
-- Try: --param leave_at=1.5 (seconds, at least 0.5).
-- Prints when the maps became right and how many messages it took.
world.set{dt = 1 / 60, duration = 2}
world.ground{friction = 0.8}

local leave_at = args.leave_at or 1.0
if type(leave_at) ~= "number" or leave_at < 0.5 then
  error("--param leave_at: seconds, at least 0.5 (after the first discovery), got " .. tostring(leave_at))
end
local function spawn(name, params)
  return world.spawn("superbot", {name = name, behavior = "behaviors/discovery.lua", params = params})
end

-- The spine s1..s4 runs along -x; branches stick out sideways and carry further modules.
local s1 = world.spawn("superbot", {at = {0, 0, 0.043}, name = "s1", behavior = "behaviors/discovery.lua"})
local s2, s3, s4 = spawn("s2"), spawn("s3"), spawn("s4")
world.connect(s1, "back", s2, "front")
world.connect(s2, "back", s3, "front")
world.connect(s3, "back", s4, "front")
local b1, b2 = spawn("b1"), spawn("b2")
world.connect(s1, "left", b1, "back")
world.connect(s2, "right", b2, "back")
local b3 = spawn("b3", {leave_at = leave_at, leave_dock = "back"})
local b4 = spawn("b4")
world.connect(s3, "left", b3, "back")
world.connect(b3, "front", b4, "back")
local b5, b6 = spawn("b5"), spawn("b6")
world.connect(s4, "right", b5, "back")
world.connect(b5, "front", b6, "left")
world.camera{eye = {0.35, -0.9, 0.9}, target = {-0.3, 0, 0}}

local mods = world.modules()

--- The truth from world.graph(): per module id, the sorted "a.dock-b.dock" keys of its
--- component's connections, and the graph's diameter in hops.
local function truth()
  local text = world.graph("json")
  local adj, edges = {}, {}
  for _, m in ipairs(mods) do adj[m.id] = {} end
  for a, da, b, db in text:gmatch('%[(%d+),"([^"]*)",(%d+),"([^"]*)"%]') do
    a, b = tonumber(a), tonumber(b)
    if a > b then a, da, b, db = b, db, a, da end
    edges[#edges + 1] = {a = a, b = b, key = string.format("%d.%s-%d.%s", a, da, b, db)}
    table.insert(adj[a], b)
    table.insert(adj[b], a)
  end
  local comp, expected, diameter = {}, {}, 0
  for _, m in ipairs(mods) do
    -- Breadth-first from m: its component, and its eccentricity.
    local dist, order, head = {[m.id] = 0}, {m.id}, 1
    while head <= #order do
      local id = order[head]
      head = head + 1
      for _, n in ipairs(adj[id]) do
        if not dist[n] then
          dist[n] = dist[id] + 1
          order[#order + 1] = n
          diameter = math.max(diameter, dist[n])
        end
      end
    end
    comp[m.id] = dist
  end
  for _, m in ipairs(mods) do
    local keys = {}
    for _, e in ipairs(edges) do
      if comp[m.id][e.a] then keys[#keys + 1] = e.key end
    end
    table.sort(keys)
    expected[m.id] = table.concat(keys, " ")
  end
  return expected, diameter, #edges
end

--- How many modules' published maps differ from the truth, and the first such module.
local function wrong()
  local expected = truth()
  local n, first = 0, nil
  for _, m in ipairs(mods) do
    local map = m:published("map")
    if not map or table.concat(map, " ") ~= expected[m.id] then
      n = n + 1
      first = first or m
    end
  end
  return n, first
end

local _, diameter0, edges0 = truth()
local slack = 3
local learned_at, relearned_at, left_at
world.on_step(function(t)
  if not left_at and not b3:dock_state("back").engaged then
    left_at = t
    local _, d, e = truth()
    print(string.format("t=%.3f s  b3 undocked: %d connections left, diameter %d", t, e, d))
  end
  local n = wrong()
  if n == 0 and not learned_at then
    learned_at = t
    print(string.format("t=%.3f s  every module's map matches world.graph() (%d connections, diameter %d): %d steps",
                        t, edges0, diameter0, math.floor(t / world.dt() + 0.5)))
  end
  if left_at and n == 0 and not relearned_at then
    relearned_at = t
    print(string.format("t=%.3f s  maps updated after the undocking: %d steps after it", t,
                        math.floor((t - left_at) / world.dt() + 0.5)))
  end
end)

world.on_end(function(t)
  local dt = world.dt()
  local steps = learned_at and math.floor(learned_at / dt + 0.5)
  expect(steps and steps <= diameter0 + slack,
         string.format("every map matched the graph within %d steps (diameter %d + %d), took %s",
                       diameter0 + slack, diameter0, slack, tostring(steps)))
  if t >= leave_at + 0.5 then
    expect(left_at ~= nil, "b3 undocked")
    local after = relearned_at and math.floor((relearned_at - left_at) / dt + 0.5)
    expect(after and after <= diameter0 + slack,
           string.format("the maps followed the undocking within %d steps, took %s", diameter0 + slack,
                         tostring(after)))
    local size = b4:published("size")
    expect(size == 2, string.format("b4 knows it is one of two now (it counts %s)", tostring(size)))
    expect(s1:published("size") == #mods - 2, string.format("s1 counts %s modules, expected %d",
                                                          tostring(s1:published("size")), #mods - 2))
  end
  local n, first = wrong()
  expect(n == 0, string.format("every map matches world.graph() at the end (%d do not, e.g. %s)", n,
                               first and first.name or "-"))
  for _, m in ipairs(mods) do expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error())) end
  local msgs = world.messages()
  print(string.format("%d messages sent, %d received", msgs.sent, msgs.received))
  world.metric("learn_steps", steps or -1)
  world.metric("messages", msgs.sent)
end)
