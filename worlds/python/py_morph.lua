-- A body grown from a genome (worlds/python/morphology.py): --param genome=a,b,c,... (whole
-- numbers). Module 1 comes first; each further module k takes three genes (p, d, f):
--   p  its parent: module (p mod (k - 1)) + 1, one already placed
--   d  the parent's dock: the first free one from dock (d mod 6) in the order
--      front, back, left, right, up, down (none free: module k is left out)
--   f  the phase of its gait, f mod 4 quarter turns (behaviors/py_morph.lua)
-- and docks its front to that dock. A body whose links overlap (a module placed into another)
-- gets metric valid = 0; every body gets metric moved, the distance (m) its centre of mass
-- moved over the ground (x and y) so far. Params: genome, seconds (duration, default 4).
world.set{dt = 1 / 60, duration = args.seconds or 4}
world.ground{friction = 0.8}

local genes = {}
for tok in string.gmatch(tostring(args.genome or ""), "[^,]+") do
  local v = math.tointeger(tonumber(tok))
  if v == nil or v < 0 then
    error("genome must be whole numbers of 0 or more separated by commas, got '" .. tok .. "'")
  end
  genes[#genes + 1] = v
end
if #genes % 3 ~= 0 or #genes > 3 * 15 then
  error("genome must hold 3 genes per module after the first, at most 45 genes; got " .. #genes)
end

local kDocks = { "front", "back", "left", "right", "up", "down" }
local behavior = "behaviors/py_morph.lua"
local mods = { world.spawn("superbot", { name = "m1", behavior = behavior, params = { phase = 0 } }) }
local used = { { } }
for k = 2, #genes // 3 + 1 do
  local p, d, f = genes[3 * k - 5], genes[3 * k - 4], genes[3 * k - 3]
  local parent = p % #mods + 1
  local dock
  for j = 0, 5 do
    local name = kDocks[(d + j) % 6 + 1]
    if not used[parent][name] then dock = name break end
  end
  if dock then
    local m = world.spawn("superbot", { name = "m" .. (#mods + 1), at = { 0, 0, 1 + #mods },
                                        behavior = behavior, params = { phase = f % 4 } })
    world.connect(mods[parent], dock, m, "front")
    used[parent][dock] = true
    mods[#mods + 1] = m
    used[#mods] = { front = true }
  end
end

-- Overlap: two links of different modules closer than 4 cm means one module sits inside another.
local kLinks = { "front_outer", "front_inner", "back_inner", "back_outer" }
local valid = 1
for i = 1, #mods do
  for j = i + 1, #mods do
    for _, a in ipairs(kLinks) do
      for _, b in ipairs(kLinks) do
        local pa, pb = mods[i]:link_position(a), mods[j]:link_position(b)
        local dx, dy, dz = pa.x - pb.x, pa.y - pb.y, pa.z - pb.z
        if dx * dx + dy * dy + dz * dz < 0.04 * 0.04 then valid = 0 end
      end
    end
  end
end
world.place_on_ground(mods[1])

local function centre()
  local x, y = 0, 0
  for _, m in ipairs(mods) do
    local q = m:position()
    x, y = x + q.x, y + q.y
  end
  return x / #mods, y / #mods
end
local x0, y0 = centre()
local function moved()
  local x, y = centre()
  return math.sqrt((x - x0) ^ 2 + (y - y0) ^ 2)
end
world.metric("valid", valid)
world.metric("modules", #mods)
world.metric("moved", 0)
world.on_step(function() world.metric("moved", moved()) end)
