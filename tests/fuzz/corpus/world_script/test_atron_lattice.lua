-- The ATRON dock layout works in the ATRON lattice (zero gravity, no behaviours):
-- 1. world.connect accepts exactly the male-female dock pairs (all 64 pairs tried; the refused
--    ones say "cannot mate"), and every accepted connect (orientation 0) places b 0.11 m from a
--    along a's dock normal with b's polar axis orthogonal to a's and b turned by the lattice rule
--    of assets/modules/atron.lua (own x axis along the lattice axis after its polar axis).
-- 2. A cluster grown with world.connect (a root, its 8 neighbours, 3 more) lies on the lattice
--    sites with the axes the lattice gives them; 6 more modules placed by hand (world.spawn with
--    quat, no connect) at free lattice sites next to it, turned by the rule in various ways.
-- 3. For EVERY pair of modules 0.11 m apart (+-1 mm), connected or not: exactly one dock of each
--    faces the other (faces within 1 mm), one is male and the other female, the normals are
--    opposite and the polar axes orthogonal. Then every facing pair that is not yet docked is
--    docked with world.connect (the engine's own gender check), which must succeed without moving
--    anything (so the docks' `up` references agree too); after 1 s everything is still in place.
world.set{gravity = {0, 0, 0}, duration = 1}
world.camera{target = {0.03, 0.03, 1.0}, eye = {0.55, -0.45, 1.35}}  -- the cluster of part 2

local kR = 0.055                 -- sphere radius
local kD = 0.11                  -- neighbours' centre distance
local kA = kD / math.sqrt(2)     -- lattice unit: neighbours differ by two units of +-kA
local kDocks = {"n0", "n1", "n2", "n3", "s0", "s1", "s2", "s3"}
-- The genders of assets/modules/atron.lua (part 1 checks this table against the engine).
local kGender = {n0 = "male", n1 = "female", n2 = "male", n3 = "female",
                 s0 = "male", s1 = "female", s2 = "male", s3 = "female"}

-- Small vector and quaternion helpers ({x, y, z} and {w, x, y, z} arrays).
local vec = require("vec")
local v3, add, sub, scale, dot, norm = vec.v3, vec.add, vec.sub, vec.scale, vec.dot, vec.norm
local q4, qmul, qconj, qrot = vec.q4, vec.qmul, vec.qconj, vec.qrot
local function fmt(v) return string.format("(%.4f, %.4f, %.4f)", v[1], v[2], v[3]) end

-- The lattice rule, for a frame q seen from a frame of reference qref (both module
-- orientations): the polar axis lies along a reference axis k and the own x axis along the
-- reference axis after k (x -> y -> z -> x). Returns ok, k.
local function ruleHolds(qref, q)
  local rel = qmul(qconj(qref), q)
  local z, x = qrot(rel, {0, 0, 1}), qrot(rel, {1, 0, 0})
  local k = 1
  for i = 2, 3 do if math.abs(z[i]) > math.abs(z[k]) then k = i end end
  local nextK = k % 3 + 1
  return math.abs(math.abs(z[k]) - 1) < 1e-6 and math.abs(math.abs(x[nextK]) - 1) < 1e-6, k
end

------------------------------------------------------------------------------------------------
-- 1. All 64 dock pairs through world.connect, on pairs of modules 1 m apart, far from the rest.
------------------------------------------------------------------------------------------------
local accepted, refused = 0, 0
do
  local k = 0
  for _, da in ipairs(kDocks) do
    for _, db in ipairs(kDocks) do
      local where = {10 + (k % 8), (k // 8), 0}
      local a = world.spawn("atron", {at = where, quat = k % 3 == 0 and {0.5, 0.5, 0.5, 0.5} or {1, 0, 0, 0}})
      local b = world.spawn("atron", {at = add(where, {0, 0, 0.5})})
      local ok, err = pcall(world.connect, a, da, b, db, 0)
      local label = da .. "-" .. db
      if kGender[da] ~= kGender[db] then
        accepted = accepted + 1
        expect(ok, label .. ": a male-female connect is accepted (" .. tostring(err) .. ")")
        if ok then
          local pa, na = v3(a:dock_position(da)), v3(a:dock_normal(da))
          local want = add(pa, scale(na, kR))
          local pb = v3(b:position())
          expect(norm(sub(pb, want)) < 1e-6,
                 label .. ": b's centre " .. fmt(pb) .. " is 0.11 m out along a's dock normal, " .. fmt(want))
          local za, zb = qrot(q4(a:orientation()), {0, 0, 1}), qrot(q4(b:orientation()), {0, 0, 1})
          expect(math.abs(dot(za, zb)) < 1e-6, label .. ": polar axes orthogonal, cos = " .. dot(za, zb))
          expect(ruleHolds(q4(a:orientation()), q4(b:orientation())), label .. ": b obeys the lattice rule")
        end
      else
        refused = refused + 1
        expect(not ok and tostring(err):find("cannot mate") ~= nil,
               label .. ": a " .. kGender[da] .. "-" .. kGender[db] .. " connect is refused with 'cannot mate', got " ..
               tostring(err))
      end
      k = k + 1
    end
  end
  expect(accepted == 32 and refused == 32, "32 pairs accepted, 32 refused")
  -- The explicit cases of the brief: two males, two females, and an orientation other than 0.
  local a = world.spawn("atron", {at = {10, 9, 0}})
  local b = world.spawn("atron", {at = {11, 9, 0}})
  local ok, err = pcall(world.connect, a, "n0", b, "s2")
  expect(not ok and tostring(err):find("cannot mate"), "male n0 to male s2 is refused: " .. tostring(err))
  ok, err = pcall(world.connect, a, "n1", b, "n3")
  expect(not ok and tostring(err):find("cannot mate"), "female n1 to female n3 is refused: " .. tostring(err))
  ok, err = pcall(world.connect, a, "n0", b, "s1", 1)
  expect(not ok, "orientation 1 is refused (the docks mate one way only): " .. tostring(err))
end

------------------------------------------------------------------------------------------------
-- 2. A cluster grown with world.connect, then modules placed by hand at lattice sites.
------------------------------------------------------------------------------------------------
-- Lattice sites: integer points with exactly two odd coordinates; the polar axis lies along the
-- even one (each module sits on a face of the cubes of side 2, its axis along the face normal).
-- The root, at site (1, 1, 0) and unturned, fixes the lattice: site p is at O + kA * (p - L0).
local kO = {0, 0, 1}
local kL0 = {1, 1, 0}
local function siteWorld(p) return add(kO, scale(sub(p, kL0), kA)) end
local function worldSite(w)  -- nearest lattice point, and how far from it (m)
  local p = add(kL0, scale(sub(w, kO), 1 / kA))
  local r = {math.floor(p[1] + 0.5), math.floor(p[2] + 0.5), math.floor(p[3] + 0.5)}
  return r, norm(sub(p, r)) * kA
end
local function siteAxis(p)  -- index of the even coordinate, or nil when p is not a site
  local odd, even = 0, nil
  for i = 1, 3 do
    if p[i] % 2 == 0 then even = i else odd = odd + 1 end
  end
  return odd == 2 and even or nil
end

local cluster = {}
local function occupied(w)
  for _, m in ipairs(cluster) do
    if norm(sub(v3(m:position()), w)) < 0.01 then return true end
  end
  return false
end
local root = world.spawn("atron", {at = kO, name = "root"})
cluster[1] = root
local opposite = {male = {"n1", "s3", "s1", "n3"}, female = {"s0", "n2", "n0", "s2"}}
local grown = 0
local function grow(a, da, variant)
  local target = add(v3(a:dock_position(da)), scale(v3(a:dock_normal(da)), kR))
  if occupied(target) then return false end
  local choices = opposite[kGender[da]]
  local db = choices[variant % #choices + 1]
  local b = world.spawn("atron", {at = {0, -3, 0}})  -- anywhere: connect places it
  local ok, err = pcall(world.connect, a, da, b, db, 0)
  expect(ok, string.format("grow %s.%s -> %s: %s", a.name, da, db, tostring(err)))
  cluster[#cluster + 1] = b
  grown = grown + 1
  return true
end
for i, d in ipairs(kDocks) do grow(root, d, i) end
for i = 2, 4 do  -- one more module on each of three neighbours, at the first free site
  for j, d in ipairs(kDocks) do
    if not cluster[i]:dock_state(d).engaged and grow(cluster[i], d, i + j) then break end
  end
end
expect(#cluster == 12, "the grown cluster has 12 modules, got " .. #cluster)

-- Every grown module sits on a lattice site with the site's polar axis and obeys the rule.
for _, m in ipairs(cluster) do
  local site, off = worldSite(v3(m:position()))
  local axis = siteAxis(site)
  local ok, k = ruleHolds({1, 0, 0, 0}, q4(m:orientation()))
  expect(off < 1e-6 and axis ~= nil,
         string.format("%s sits on a lattice site (nearest (%d,%d,%d), %.2g m off)", m.name, site[1], site[2], site[3], off))
  expect(ok and k == axis, m.name .. ": polar axis along the site's axis and own x along the next lattice axis")
end

-- Hand-placed modules: at the first free sites next to the cluster, turned by the rule (polar
-- axis along the site's axis, own x along the next lattice axis), in all four ways allowed
-- (either pole first, either way along x).
local kAxisTurn = {{0.5, 0.5, 0.5, 0.5},     -- polar axis along x: +120 deg about (1,1,1), own z -> x, x -> y
                   {0.5, -0.5, -0.5, -0.5},  -- along y: -120 deg about (1,1,1), own z -> y, x -> z
                   {1, 0, 0, 0}}             -- along z: unturned
local kVariant = {{1, 0, 0, 0}, {0, 0, 0, 1}, {0, 1, 0, 0}, {0, 0, 1, 0}}  -- own frame: none, 180 z, 180 x, 180 y
local placed = {}
do
  local count = 0
  for z = -2, 2 do
    for y = -1, 3 do
      for x = -1, 3 do
        local p = {x, y, z}
        local axis = siteAxis(p)
        local w = siteWorld(p)
        if count < 6 and axis and not occupied(w) then
          local nextToCluster = false
          for _, m in ipairs(cluster) do
            if math.abs(norm(sub(v3(m:position()), w)) - kD) < 1e-6 then nextToCluster = true end
          end
          if nextToCluster then
            count = count + 1
            local q = qmul(kAxisTurn[axis], kVariant[count % 4 + 1])
            local m = world.spawn("atron", {at = w, quat = q, name = "placed_" .. count})
            local ok, k = ruleHolds({1, 0, 0, 0}, q4(m:orientation()))
            expect(ok and k == axis, m.name .. " is turned by the rule (polar axis " .. tostring(k) .. ", site axis " .. axis .. ")")
            placed[#placed + 1] = m
            cluster[#cluster + 1] = m
          end
        end
      end
    end
  end
  expect(#placed == 6, "6 modules placed by hand, got " .. #placed)
end

------------------------------------------------------------------------------------------------
-- 3. Every neighbour pair in the world: facing docks male-female, axes orthogonal.
------------------------------------------------------------------------------------------------
local function neighbourPairs()
  local mods = world.modules()
  local docks = {}
  for i, m in ipairs(mods) do
    docks[i] = {}
    for _, d in ipairs(kDocks) do docks[i][d] = {pos = v3(m:dock_position(d)), normal = v3(m:dock_normal(d))} end
  end
  local out = {}
  for i = 1, #mods do
    for j = i + 1, #mods do
      local a, b = mods[i], mods[j]
      local dist = norm(sub(v3(a:position()), v3(b:position())))
      if math.abs(dist - kD) < 0.001 then
        local facing = {}
        for _, da in ipairs(kDocks) do
          for _, db in ipairs(kDocks) do
            if norm(sub(docks[i][da].pos, docks[j][db].pos)) < 0.001 then
              facing[#facing + 1] = {da = da, db = db, cos = dot(docks[i][da].normal, docks[j][db].normal)}
            end
          end
        end
        out[#out + 1] = {a = a, b = b, facing = facing}
      end
    end
  end
  return out
end

local function checkPairs(when)
  local pairsFound = neighbourPairs()
  local unconnected = 0
  for _, p in ipairs(pairsFound) do
    local label = string.format("%s: %s-%s", when, p.a.name, p.b.name)
    expect(#p.facing == 1, label .. ": exactly one pair of facing docks, got " .. #p.facing)
    local f = p.facing[1]
    if f then
      label = label .. string.format(" (%s-%s)", f.da, f.db)
      expect(kGender[f.da] ~= kGender[f.db], label .. ": facing docks are " .. kGender[f.da] .. " and " .. kGender[f.db])
      expect(f.cos < -0.99999, label .. ": facing normals opposite, cos = " .. f.cos)
      local s = p.a:dock_state(f.da)
      if not (s.engaged and s.peer_module == p.b.id and s.peer_dock == f.db) then unconnected = unconnected + 1 end
    end
    local za, zb = qrot(q4(p.a:orientation()), {0, 0, 1}), qrot(q4(p.b:orientation()), {0, 0, 1})
    expect(math.abs(dot(za, zb)) < 1e-3, label .. ": polar axes orthogonal, cos = " .. dot(za, zb))
  end
  return pairsFound, unconnected
end

local pairs0, unconnected0 = checkPairs("at start")
log(string.format("%d neighbour pairs, %d of them not docked by a connect call", #pairs0, unconnected0))
-- 32 from part 1, 11 connects in the cluster, and many more facing pairs that no connect made.
expect(#pairs0 >= 32 + 11 + 20, "at least 63 neighbour pairs, got " .. #pairs0)
expect(unconnected0 >= 20, "at least 20 neighbour pairs checked that no connect made, got " .. unconnected0)

-- The engine's own check: dock every facing pair not docked yet; nothing may move.
local before = {}
for _, m in ipairs(world.modules()) do before[m.id] = {pos = v3(m:position()), rot = q4(m:orientation())} end
local docked = 0
for _, p in ipairs(pairs0) do
  local f = p.facing[1]
  if f and not p.a:dock_state(f.da).engaged then
    local ok, err = pcall(world.connect, p.a, f.da, p.b, f.db, 0)
    expect(ok, string.format("connect %s.%s to %s.%s where they face each other: %s", p.a.name, f.da, p.b.name, f.db, tostring(err)))
    if ok then docked = docked + 1 end
  end
end
expect(docked == unconnected0, string.format("docked all %d facing pairs, got %d", unconnected0, docked))
local function checkStill(when, tol)
  for _, m in ipairs(world.modules()) do
    local b = before[m.id]
    local moved = norm(sub(v3(m:position()), b.pos))
    local q = q4(m:orientation())
    local turn = 2 * math.acos(math.min(1, math.abs(q[1] * b.rot[1] + q[2] * b.rot[2] + q[3] * b.rot[3] + q[4] * b.rot[4])))
    expect(moved < tol and turn < tol * 10,
           string.format("%s: %s moved %.3g m and turned %.3g rad", when, m.name, moved, turn))
  end
end
checkStill("after docking every facing pair", 1e-6)

world.at(1, function()
  local pairs1, unconnected1 = checkPairs("after 1 s")
  expect(#pairs1 == #pairs0, string.format("after 1 s: still %d neighbour pairs, got %d", #pairs0, #pairs1))
  expect(unconnected1 == 0, "after 1 s: every facing pair is docked, " .. unconnected1 .. " are not")
  checkStill("after 1 s", 1e-4)
end)
