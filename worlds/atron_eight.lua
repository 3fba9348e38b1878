-- Seven ATRONs in an 8-shape (the paper's Fig. 1(f)): two closed four-module rings of the ATRON
-- lattice that share one module, standing upright, held at the shared module `c` as on a stand
-- (spawned with fixed = true, 0.3 m above the ground).
--
--        b       e          ring A: a b c d, ring B: c e f g; c belongs to both.
--      a   c   f            Neighbours are 0.11 m apart along (+-1, 0, +-1)/sqrt2 (x along the 8,
--        d       g          z up).
--
-- Built with world.connect: each ring is three connects and a fourth between docks that already
-- face each other (closing the loop), so all eight connections are male to female.
-- How it moves. Each module's polar axis is orthogonal to its neighbours' (x for a, c, f; z for
-- b, d, e, g), and each module's two ring neighbours sit on the same hemisphere, so no ring
-- straddles an equator and locks a joint. The shared module c carries ring B on its held
-- (north) hemisphere and ring A on the other, so its equator turns ring A about the 8's long axis
-- like a propeller (behaviors/atron_eight.lua: 1 rad/s, the motor's limit, from t = 1 s); ring A
-- is symmetric about that axis, so gravity neither helps nor brakes it. The other six hold their
-- equators.
-- Checks (a full run): ring A turned more than 1.5 turns, its modules kept their distance from
-- the axis and from each other (within 2 mm), ring B stayed where it was, every connection held,
-- no module faulted.
--   ./build/rm3d run worlds/atron_eight.lua --png out/atron_eight.png [--param spin=-0.5]
world.set{duration = 12}
world.ground{friction = 1.0}

local vec = require("vec")
local atron = require("atron")
local kA = 0.11 / math.sqrt(2) -- lattice unit: neighbours' centres differ by one unit in two axes
local kHeight = 0.3
local spin = args.spin or 1
local hold = {}

local connections = {}
--- Spawns a module docked to a's dock pointing along dir (any dock of the other gender puts it
--- on the lattice).
local function attach(a, dir, name)
  local da = atron.dock_toward(a, dir)
  local b = world.spawn("atron", {name = name, behavior = "behaviors/atron_eight.lua", params = hold})
  local db = atron.male[da] and "s1" or "s0"
  world.connect(a, da, b, db)
  connections[#connections + 1] = {a = a, da = da, b = b, db = db}
  return b
end

--- Closes a ring between a and b, already neighbours in the lattice.
local function close(a, b)
  local d = vec.sub(vec.v3(b:position()), vec.v3(a:position()))
  local da, db = atron.dock_toward(a, d), atron.dock_toward(b, vec.scale(d, -1))
  world.connect(a, da, b, db)
  connections[#connections + 1] = {a = a, da = da, b = b, db = db}
end

-- c: polar axis along x (own z -> x, own x -> y, as the lattice's cyclic rule wants), north
-- towards +x: ring B (+x) docks on its held north hemisphere, ring A (-x) on the south one.
local c = world.spawn("atron", {at = {0, 0, kHeight}, quat = {0.5, 0.5, 0.5, 0.5}, name = "c", fixed = true,
                                behavior = "behaviors/atron_eight.lua", params = {spin = spin}})
local b = attach(c, {-1, 0, 1}, "b")
local a = attach(b, {-1, 0, -1}, "a")
local d = attach(a, {1, 0, -1}, "d")
close(d, c)
local e = attach(c, {1, 0, 1}, "e")
local f = attach(e, {1, 0, -1}, "f")
local g = attach(f, {-1, 0, -1}, "g")
close(g, c)
-- A post under c shows the stand (c's hold is what keeps the 8 up; the post stays clear of both rings).
world.box{size = {0.03, 0.03, kHeight - 0.057}, at = {0, 0, (kHeight - 0.057) / 2}}
world.camera{eye = {0.2, -0.75, 0.4}, target = {0, 0, kHeight - 0.06}}

local mods = world.modules()
local ringA, ringB = {a, b, d}, {e, f, g}
local start = {}
for _, m in ipairs(mods) do start[m.name] = vec.v3(m:position()) end
local axis = vec.v3(c:position()) -- the long axis runs along x through c
local function fromAxis(m)
  local p = vec.v3(m:position())
  return math.sqrt((p[2] - axis[2]) ^ 2 + (p[3] - axis[3]) ^ 2)
end
local radius0 = {}
for _, m in ipairs(ringA) do radius0[m.name] = fromAxis(m) end
local pairsA = {{a, b}, {b, d}, {a, d}}
local apart0 = {}
for i, p in ipairs(pairsA) do apart0[i] = vec.dist(vec.v3(p[1]:position()), vec.v3(p[2]:position())) end

-- Ring A's turn, unwrapped, from b's angle about the axis.
local function angleOf(m)
  local p = vec.v3(m:position())
  return math.atan(p[2] - axis[2], p[3] - axis[3])
end
local turned, last = 0, angleOf(b)
local worstRadius, worstApart, worstB = 0, 0, 0
world.on_step(function()
  local now = angleOf(b)
  turned = turned + ((now - last + math.pi) % (2 * math.pi) - math.pi)
  last = now
  for _, m in ipairs(ringA) do worstRadius = math.max(worstRadius, math.abs(fromAxis(m) - radius0[m.name])) end
  for i, p in ipairs(pairsA) do
    worstApart = math.max(worstApart, math.abs(vec.dist(vec.v3(p[1]:position()), vec.v3(p[2]:position())) - apart0[i]))
  end
  for _, m in ipairs(ringB) do worstB = math.max(worstB, vec.dist(vec.v3(m:position()), start[m.name])) end
end)

world.every(2, function(t)
  print(string.format("t=%4.1f s  ring A turned %6.1f deg  (b at y=%+.3f z=%.3f)", t, math.deg(turned),
                      b:position().y, b:position().z))
end)

world.on_end(function(t)
  for _, m in ipairs(mods) do expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error())) end
  atron.expect_connected(connections)
  expect(worstRadius < 0.002 and worstApart < 0.002,
         string.format("ring A kept its shape: radius within %.4f m, distances within %.4f m (2 mm)", worstRadius,
                       worstApart))
  expect(worstB < 0.002, string.format("ring B stayed put: moved %.4f m at most", worstB))
  world.metric("ring_a_turns", math.abs(turned) / (2 * math.pi))
  print(string.format("ring A turned %.2f turns; its radius changed by %.2f mm and its distances by %.2f mm at most; "
                      .. "ring B moved %.2f mm", math.abs(turned) / (2 * math.pi), worstRadius * 1000, worstApart * 1000,
                      worstB * 1000))
  if t < 12 then return end -- a shorter run (the sample test's 2 s) checks only the above
  local turns = math.abs(turned) / (2 * math.pi)
  expect(turns > 1.5, string.format("ring A turned %.2f turns in %.0f s, expected more than 1.5", turns, t))
end)
