-- The reconfiguration planner (lua/reconfig.lua) on shapes alone, no physics: an 8-module snake
-- to the sprawling quadruped "walker8" (a head, a 3-module body, four one-module legs on the
-- first and last body modules' side docks) takes 8 dock operations, the fewest possible, and
-- back again 8; a snake to itself with its modules named in another order takes none; a plan
-- between shapes of different sizes or types is refused with a message; shape errors name the
-- entry; the shape of a world of docked SuperBots (reconfig.from_world) is its snake.
local reconfig = require("reconfig")
world.set{duration = 0.05}

local function snake(n, prefix)
  local names, conns = {}, {}
  for i = 1, n do names[i] = prefix .. i end
  for i = 1, n - 1 do conns[i] = {names[i], "back", names[i + 1], "front"} end
  return reconfig.shape{modules = names, connections = conns}
end

local walker8 = reconfig.shape{
  modules = {"h", "b1", "b2", "b3", "lf", "rf", "lr", "rr"},
  connections = {
    {"h", "back", "b1", "front"}, {"b1", "back", "b2", "front"}, {"b2", "back", "b3", "front"},
    {"b1", "left", "lf", "front"}, {"b1", "right", "rf", "front"},
    {"b3", "left", "lr", "front"}, {"b3", "right", "rr", "front"},
  },
}

local s8 = snake(8, "s")
local p = reconfig.plan(s8, walker8)
print(reconfig.format(p))
local undocks, docks = 0, 0
for _, o in ipairs(p.ops) do
  if o.op == "undock" then undocks = undocks + 1 else docks = docks + 1 end
end
expect(#p.ops == 8 and undocks == 4 and docks == 4, "snake to walker8: 4 undocks and 4 docks, got " ..
       undocks .. " and " .. docks)
expect(p.lower_bound == 8 and p.kept == 3, "the fewest possible is 8 and 3 connections are kept, got " ..
       p.lower_bound .. " and " .. p.kept)
-- The undocks come first, and the kept chain is the snake's head: s1 to s4 are the head and body.
expect(p.ops[1].op == "undock" and p.ops[#p.ops].op == "dock", "undocks first, docks last")
expect(p.role.s1 == "h" and p.role.s2 == "b1" and p.role.s3 == "b2" and p.role.s4 == "b3",
       "the head and body are s1 to s4, got " .. tostring(p.role.s1) .. " " .. tostring(p.role.s4))
-- Every dock operation joins a leg's front to a body module's side.
for _, o in ipairs(p.ops) do
  if o.op == "dock" then
    expect((o[1] == "s2" or o[1] == "s4") and (o[2] == "left" or o[2] == "right") and o[4] == "front",
           "a leg docks to b1 or b3's side: " .. table.concat(o, " "))
  end
end

local back = reconfig.plan(walker8, s8)
expect(#back.ops == 8 and back.lower_bound == 8, "walker8 to a snake: 8 operations, got " .. #back.ops)

-- The same snake named in another order: every module takes a role, nothing moves.
local names, conns = {}, {}
for i = 1, 8 do names[i] = "m" .. (9 - i) end
for i = 1, 7 do conns[i] = {names[i], "back", names[i + 1], "front"} end
local same = reconfig.plan(s8, reconfig.shape{modules = names, connections = conns})
expect(#same.ops == 0 and same.kept == 7, "a snake to itself: no operation, got " .. #same.ops)

-- Refusals.
local ok, err = pcall(function() local q = reconfig.plan(snake(7, "s"), walker8); return q end)
expect(not ok and err:find("the shapes hold 7 and 8 modules; a plan needs the same modules", 1, true),
       "different sizes refused: " .. tostring(err))
-- The error names this file and line (the call of plan), not the library's.
expect(err:find("reconfig_plan%.lua:%d+: reconfig%.match") ~= nil, "the error names the caller: " .. tostring(err))
ok, err = pcall(reconfig.plan, reconfig.shape{modules = {a = "superbot", b = "atron"}},
                reconfig.shape{modules = {a = "superbot", b = "superbot"}})
expect(not ok and err:find("different numbers of 'atron' modules", 1, true), "types must match: " .. tostring(err))
-- (the first type in name order that differs: 'atron' before 'superbot')
ok, err = pcall(reconfig.shape, {modules = {"a", "b"}, connections = {{"a", "back", "c", "front"}}})
expect(not ok and err:find("connections[1]: unknown module 'c'", 1, true), "unknown module named: " .. tostring(err))
ok, err = pcall(reconfig.shape, {modules = {"a", "b", "c"},
                                 connections = {{"a", "back", "b", "front"}, {"a", "back", "c", "front"}}})
expect(not ok and err:find("connections[2]: dock a.back is in two connections", 1, true),
       "a dock used twice named: " .. tostring(err))

-- Larger shapes plan too: a 32-module snake to four 8-module walkers' worth of legs on one body.
local big = snake(32, "s")
local conns32 = {}
for i = 1, 23 do conns32[#conns32 + 1] = {"r" .. i, "back", "r" .. (i + 1), "front"} end
for k = 0, 3 do
  local body = 2 + 6 * k
  conns32[#conns32 + 1] = {"r" .. body, "left", "r" .. (25 + 2 * k), "front"}
  conns32[#conns32 + 1] = {"r" .. body, "right", "r" .. (26 + 2 * k), "front"}
end
local names32 = {}
for i = 1, 32 do names32[i] = "r" .. i end
local p32 = reconfig.plan(big, reconfig.shape{modules = names32, connections = conns32})
expect(#p32.ops == p32.lower_bound and #p32.ops == 16,
       "32 modules: 8 legs moved in 16 operations, the fewest; got " .. #p32.ops .. " (at least " .. p32.lower_bound .. ")")

-- The shape of the world: three SuperBots docked back to front, and a fourth left apart.
world.ground{}
local a = world.spawn("superbot", {name = "a", at = {0, 0, 0.05}})
local b = world.spawn("superbot", {name = "b"})
local c = world.spawn("superbot", {name = "c"})
world.spawn("superbot", {name = "d", at = {0, 1, 0.05}})
world.connect(a, "back", b, "front")
world.connect(b, "back", c, "front")
world.at(0.02, function()
  local now = reconfig.from_world(world)
  expect(#now.names == 4 and #now.edges == 2, "the world's shape: 4 modules, 2 connections, got " ..
         #now.names .. " and " .. #now.edges)
  local line = reconfig.shape{modules = {a = "superbot", b = "superbot", c = "superbot", d = "superbot"},
                              connections = {{"a", "back", "b", "front"}, {"b", "back", "c", "front"}}}
  local q = reconfig.plan(now, line)
  expect(#q.ops == 0 and q.kept == 2, "the world is the 3-snake and a loose module: nothing to do, got " .. #q.ops)
  local joined = reconfig.shape{modules = {a = "superbot", b = "superbot", c = "superbot", d = "superbot"},
                                connections = {{"a", "back", "b", "front"}, {"b", "back", "c", "front"},
                                               {"c", "back", "d", "front"}}}
  local r = reconfig.plan(now, joined)
  expect(#r.ops == 1 and r.ops[1].op == "dock" and r.ops[1][1] == "c" and r.ops[1][3] == "d",
         "joining d to the tail is one dock operation: " .. reconfig.format(r))
end)

-- The steps that carry a plan out on the ground (lua/lay_retrieve.lua): the snake lays its last
-- four modules in two rounds, each followed by a crawl; what they build is walker8.
local layRetrieve = require("lay_retrieve")
local steps, built = layRetrieve.compile(s8, walker8)
expect(steps ~= nil and #steps == 13, "snake to walker8: 13 steps, got " .. tostring(steps and #steps or built))
-- Each mover turns its yaw back after its cut, but s5: it is laid next, for the chain's last module,
-- and keeps its yaw turned until it is captured (turning back would push s6 out of s4's reach).
local straightened = {}
for _, st in ipairs(steps or {}) do
  if st.kind == "sweep" and st.joint == "yaw" and st.angle == 0 then straightened[#straightened + 1] = st.owner end
end
expect(table.concat(straightened, " ") == "s7 s6 s4", "s7, s6 and s4 turn their yaws back, s5 does not: " ..
       table.concat(straightened, " "))
local crawls = {}
for _, st in ipairs(steps or {}) do
  if st.kind == "crawl" then crawls[#crawls + 1] = st.owner .. ":" .. #st.chain end
end
expect(table.concat(crawls, " ") == "s2:6 s4:4", "two crawls, s1..s6 for s2's legs and s1..s4 for s4's: " ..
       table.concat(crawls, " "))
expect(steps and #reconfig.plan(reconfig.shape(built), walker8).ops == 0, "the steps build walker8")
-- And back: walker8 to a snake lets the legs go and takes them at the tail, rear pair first (20
-- steps, two crawls forward per pair), and what the steps build is the snake.
local backSteps, backBuilt = layRetrieve.compile(walker8, s8)
expect(backSteps ~= nil and #backSteps == 20, "walker8 to a snake: 20 steps, got " ..
       tostring(backSteps and #backSteps or backBuilt))
local forward = {}
for _, st in ipairs(backSteps or {}) do
  if st.kind == "crawl" and st.forward then forward[#forward + 1] = st.owner .. "." .. st.sockets[1][1] .. ":" .. st.sockets[1][2] end
end
expect(table.concat(forward, " ") == "b3.back:lr lr.back:rr rr.back:lf lf.back:rf",
       "four crawls forward, each ending when the tail (the last leg taken) takes the next: " ..
       table.concat(forward, " "))
expect(backSteps and #reconfig.plan(reconfig.shape(backBuilt), s8).ops == 0, "the steps build a snake")
-- Shapes it cannot build say why.
local none, why = layRetrieve.compile(reconfig.shape{modules = {"a", "b", "c", "d"},
                                                     connections = {{"a", "left", "b", "back"}}}, s8)
expect(none == nil and why:find("not a snake", 1, true), "from neither a snake nor a walker: " .. tostring(why))
local ring = reconfig.shape{modules = {"a", "b", "c", "d"}, connections = {{"a", "back", "b", "front"},
                             {"b", "left", "c", "back"}, {"c", "front", "d", "back"}}}
none, why = layRetrieve.compile(snake(4, "s"), ring)
expect(none == nil and why:find("one-module legs", 1, true), "to a shape without legs: " .. tostring(why))
