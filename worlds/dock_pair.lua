-- worlds/dock_pair.lua: docking on the ground. Two pairs of SuperBots rest on the ground with
-- their docks facing: front to back 15 mm apart, and front to front 20 mm apart and 10 deg off in
-- yaw; a pair of ATRONs lies on their sides, a male dock facing a female one 15 mm apart. Docks start enabled: a capture joint draws each pair's faces together (equal and opposite,
-- at up to 5 cm/s and 20 N, solved with the contacts, so the pair's centre stays put and nothing
-- tips) and they latch. Each pair then undocks (one module disables its dock), waits and docks
-- again (behaviors/dock_cycle.lua).
--
--   rm3d run worlds/dock_pair.lua
--
-- Checks at the end: every pair latched twice, each time within 3 s; the pairs' centres moved
-- less than 5 mm. Metrics: first_latch_s, second_latch_s (the later pair's), centre_moved_mm.
world.set{duration = 6}
world.ground{friction = 0.8}

local cycle = "behaviors/dock_cycle.lua"
-- Front to back: b's front dock 15 mm behind a's back dock.
local a1 = world.spawn("superbot", {name = "a1", at = {0, 0, 0.1}})
local b1 = world.spawn("superbot", {name = "b1", behavior = cycle, params = {dock = "front"}})
world.place_facing(a1, "back", b1, "front", 0.015)
-- Front to front, 10 deg off: b's front dock 20 mm ahead of a's, turned about the vertical.
local a2 = world.spawn("superbot", {name = "a2", at = {0, 0.5, 0.1}})
local yaw = math.rad(10)
local b2 = world.spawn("superbot", {name = "b2", at = {0.115 + 0.095 * math.cos(yaw), 0.5 + 0.095 * math.sin(yaw), 0.1},
                                    rot = {0, 0, math.pi + yaw}, behavior = cycle, params = {dock = "front"}})
for _, m in ipairs({a1, b1, a2, b2}) do world.place_on_ground(m) end
-- Two ATRONs lying on their sides (polar axis level), so a male dock of each hemisphere points
-- level: b's female s1 faces a's male n0 15 mm away (gendered docks mate male to female).
local a3 = world.spawn("atron", {name = "a3", at = {0, 1, 0.2}, rot = {math.pi / 2, 0, 0}})
world.place_on_ground(a3)
local b3 = world.spawn("atron", {name = "b3", behavior = cycle, params = {dock = "s1"}})
world.place_facing(a3, "n0", b3, "s1", 0.015)
world.place_on_ground(b3)

local pairs_ = {{a = a1, b = b1, dock = "back"}, {a = a2, b = b2, dock = "front"}, {a = a3, b = b3, dock = "n0"}}
local function centre(p)
  local x, y = p.a:position(), p.b:position()
  return {(x.x + y.x) / 2, (x.y + y.y) / 2}
end
world.at(0.25, function()  -- all settled on their brackets and hulls
  for _, p in ipairs(pairs_) do p.c0 = centre(p) end
end)
world.on_step(function(t)
  for _, p in ipairs(pairs_) do
    local engaged = p.a:dock_state(p.dock).engaged
    if engaged and not p.first then
      p.first = t
      local c = centre(p)
      p.moved = math.sqrt((c[1] - p.c0[1]) ^ 2 + (c[2] - p.c0[2]) ^ 2)
    end
    if p.first and not engaged and not p.apart then p.apart = t end
    if p.apart and engaged and not p.second then p.second = t end
  end
end)

world.on_end(function(t)
  local first, second, moved = 0, 0, 0
  for _, p in ipairs(pairs_) do
    print(string.format("%s-%s: latched at %s s, released at %s s, latched again at %s s; centre moved %.2f mm",
                        p.a.name, p.b.name, tostring(p.first), tostring(p.apart), tostring(p.second),
                        (p.moved or 0) * 1000))
    for _, m in ipairs({p.a, p.b}) do expect(m:error() == nil, m.name .. " did not fault") end
    if t >= 6 then
      expect(p.first and p.first <= 3, p.a.name .. " and " .. p.b.name .. " latched within 3 s")
      expect(p.second and p.second - p.apart <= 3, p.a.name .. " and " .. p.b.name .. " latched again within 3 s")
      expect(p.moved and p.moved < 0.005, "the pair's centre moved less than 5 mm")
    end
    first = math.max(first, p.first or 0)
    second = math.max(second, p.second and p.second - p.apart or 0)
    moved = math.max(moved, p.moved or 0)
  end
  world.metric("first_latch_s", first)
  world.metric("second_latch_s", second)
  world.metric("centre_moved_mm", moved * 1000)
end)
