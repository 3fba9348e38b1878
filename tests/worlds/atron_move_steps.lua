-- The ATRON move compiler (lua/atron_moves.lua) on shapes alone, no physics: a module moved from
-- one carrier to a module two sites away takes one half turn and one release; the compiler places
-- the modules where world.connect does; the way back, a connection no half turn can make, a
-- shape that does not close on the lattice and a dock name an ATRON lacks are refused with their
-- reasons.
local reconfig = require("reconfig")
local moves = require("atron_moves")
world.set{duration = 0.05, gravity = {0, 0, 0}}

local mods = {a = "atron", b = "atron", c = "atron", d = "atron"}
local start = {{"a", "n1", "b", "s0"}, {"b", "n2", "c", "s1"}, {"c", "n1", "d", "n0"}}
local now = reconfig.shape{modules = mods, connections = start}
local moved = reconfig.shape{modules = mods, connections = {{"a", "s1", "d", "s0"}, {"b", "n2", "c", "s1"},
                                                            {"c", "n1", "d", "n0"}}}

local steps, built = moves.compile(now, moved)
expect(steps ~= nil, "a to d compiles: " .. tostring(built))
if steps then
  print(moves.format(steps))
  expect(#steps == 2 and steps[1].kind == "turn" and steps[1].owner == "b" and steps[1].hemisphere == "s" and
         steps[1].mover == "a", "first b turns its south hemisphere carrying a")
  expect(#steps[1].latches == 1, "the turn makes one connection, got " .. #steps[1].latches)
  expect(steps[2].kind == "release" and steps[2].owner == "a" and steps[2].from == "b" and steps[2].dock == "n1",
         "then a lets go of b")
  expect(#reconfig.plan(reconfig.shape(built), moved).ops == 0, "they build the target")
end

-- Back again is not one half turn: a hangs on d's south hemisphere, whose half turn takes a
-- elsewhere.
local back, why = moves.compile(moved, now)
expect(back == nil and why == "no half turn of a module brings a.n1 to b.s0", "the way back is refused: " .. tostring(why))

-- The compiler's lattice is world.connect's: the same four placed by world.connect are as far
-- apart, pair by pair, as moves.place puts them (a and d start sqrt(5) lattice steps apart).
local m = {}
for _, n in ipairs({"a", "b", "c", "d"}) do m[n] = world.spawn("atron", {name = n, at = n == "b" and {0, 0, 1} or nil}) end
for _, e in ipairs(start) do world.connect(m[e[3]], e[4], m[e[1]], e[2]) end
local placed = moves.place(now)
for _, x in ipairs({"a", "b", "c", "d"}) do
  for _, y in ipairs({"a", "b", "c", "d"}) do
    local px, py = m[x]:position(), m[y]:position()
    local world_d = math.sqrt((px.x - py.x) ^ 2 + (px.y - py.y) ^ 2 + (px.z - py.z) ^ 2)
    local qx, qy = placed[x].p, placed[y].p
    local lattice_d = math.sqrt((qx[1] - qy[1]) ^ 2 + (qx[2] - qy[2]) ^ 2 + (qx[3] - qy[3]) ^ 2)
    expect(math.abs(world_d - lattice_d) < 1e-6, string.format("%s-%s: %.5f m placed, %.5f m by world.connect", x, y,
                                                                lattice_d, world_d))
  end
end
local pa, pd = m.a:position(), m.d:position()
local gap = math.sqrt((pa.x - pd.x) ^ 2 + (pa.y - pd.y) ^ 2 + (pa.z - pd.z) ^ 2)
expect(math.abs(gap - 0.11 * math.sqrt(5)) < 1e-3, string.format("a and d start sqrt(5) lattice steps apart: %.4f m", gap))

-- Connections that do not close on the lattice: two docks on opposite sides of a holding one b.
local bad = reconfig.shape{modules = {a = "atron", b = "atron"}, connections = {{"a", "n0", "b", "n1"}, {"a", "n2", "b", "n3"}}}
local no, msg = moves.compile(bad, bad)
expect(no == nil and tostring(msg):find("do not fit the ATRON lattice (a.n2-b.n3)", 1, true),
       "a shape that does not close is refused: " .. tostring(msg))

-- A target whose new connection is a quarter turn away: no half turn brings it.
local quarter = reconfig.shape{modules = mods, connections = {{"a", "n1", "c", "n0"}, {"b", "n2", "c", "s1"},
                                                              {"c", "n1", "d", "n0"}}}
local q, qwhy = moves.compile(now, quarter)
expect(q == nil and qwhy:find("no half turn", 1, true), "a connection no half turn makes is refused: " .. tostring(qwhy))

-- A dock name an ATRON does not have: refused with the connection's end named.
local front = reconfig.shape{modules = mods, connections = {{"a", "front", "d", "s0"}, {"b", "n2", "c", "s1"},
                                                            {"c", "n1", "d", "n0"}}}
local f, fwhy = moves.compile(now, front)
expect(f == nil and fwhy == "a.front: an ATRON has no dock 'front' (n0-n3, s0-s3)", "an unknown dock is refused: " .. tostring(fwhy))
