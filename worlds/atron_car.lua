-- The ATRON car (the paper's Fig. 5, bottom): seven ATRONs docked in the ATRON lattice with
-- world.connect, driving forward (+x) on the ground on four wheel modules.
--
--   chassis  `front` and `rear` lie with their polar axes along x (the driving direction) and
--            `middle` bridges them from above, its axis across; their equators hold 0
--            (behaviors/hold.lua), so the chassis is rigid.
--   wheels   `wheel_fl`, `wheel_fr` hang under `front`, `wheel_rl`, `wheel_rr` under `rear`, one
--            lattice step out, down and to the side. Each is docked by its inner hemisphere, and
--            its equator spins the outer hemisphere at 1 rad/s, the motor's limit
--            (behaviors/atron_wheel.lua), the sign worked out below from how the wheel lies.
--
-- The lattice is turned 45 degrees about x, so the wheel axes point down and outwards at 45
-- degrees and every wheel stands on its OUTER hemisphere (on the connector that points
-- straight down). A wheel with a horizontal axis would stand on its equator, on the rims of both
-- hemispheres at once, and the held inner rim would drag along the ground as the outer one
-- rolls: tried, such a car (four horizontal wheels under two upright chassis modules) creeps
-- 2 mm in 10 s. Tilted, each wheel rolls on a circle of radius 0.055 cos 45 = 0.039 m, so the car
-- drives 0.039 m/s: about 0.39 m in 10 s.
--
-- The checks: it drove forward more than 0.3 m, kept straight, stayed upright, and stayed in one
-- piece (every module keeps its distances to the others within 5 mm, the six connections made
-- here still engaged). (Front and rear wheel pairs also face each other on their inner, held
-- hemispheres, male to female; an engine that docks facing docks by itself may join them too,
-- which changes nothing: both halves are part of the chassis.)
--
--   ./build/rm3d run worlds/atron_car.lua --png out/atron_car.png [--param speed=0.5]
world.set{duration = 10}
world.ground{friction = 1.0}

local kR = 0.056                 -- a wheel's centre height: radius 0.055 + the 1 mm hull margin
local kA = 0.11 / math.sqrt(2)   -- lattice unit: neighbours' centres differ by two steps of kA
local kH = math.sqrt(0.5)
local kSpeed = args.speed or 1   -- wheel speed, rad/s
local kDocks = require("atron").docks
local kMale = require("atron").male
local kHold = {targets = {equator = 0}}

local vec = require("vec")
local atron = require("atron")
local v3, dot, dist, qmul, qrot = vec.v3, vec.dot, vec.dist, vec.qmul, vec.qrot
local dockToward, outerPole = atron.dock_toward, atron.outer_pole

-- Spawns a module and docks it to a's dock pointing along dir (any dock of the other gender
-- puts it on the lattice). A wheel gets the equator speed that rolls it forward: the outer
-- hemisphere must turn about +y (z up, x forward), and a positive equator speed turns the
-- outer hemisphere about minus its own pole, whichever hemisphere is outer.
local connections = {}
local function attach(a, dir, name, wheel)
  local da = dockToward(a, dir)
  local opts = {name = name, behavior = "behaviors/hold.lua", params = kHold}
  if wheel then
    local forward = dot(outerPole(a, da), {0, 1, 0}) > 0 and -1 or 1
    opts = {name = name, behavior = "behaviors/atron_wheel.lua", params = {speed = forward * kSpeed}}
  end
  local b = world.spawn("atron", opts)
  local db = kMale[da] and "s1" or "s0"
  world.connect(a, da, b, db)
  connections[#connections + 1] = {a = a, da = da, b = b, db = db}
  return b
end

-- `front`: polar axis along x (own z -> x, own x -> y), then the lattice turn of 45 deg about x.
local axisX = {0.5, 0.5, 0.5, 0.5}
local tilt = {math.cos(math.pi / 8), math.sin(math.pi / 8), 0, 0}
local front = world.spawn("atron", {at = {0, 0, kR + kA * kH + 0.0005}, quat = qmul(tilt, axisX), name = "front",
                                    behavior = "behaviors/hold.lua", params = kHold})
local middle = attach(front, {-1, kH, kH}, "middle")
local rear = attach(middle, {-1, -kH, -kH}, "rear")
attach(front, {1, kH, -kH}, "wheel_fl", true)
attach(front, {1, -kH, -kH}, "wheel_fr", true)
attach(rear, {-1, kH, -kH}, "wheel_rl", true)
attach(rear, {-1, -kH, -kH}, "wheel_rr", true)
world.camera{follow = front, eye = {0.25, -0.55, 0.3}}

local mods = world.modules()
local start = v3(front:position())
local apart = {}  -- initial distances between module centres
for i = 1, #mods do
  apart[i] = {}
  for j = 1, #mods do apart[i][j] = dist(v3(mods[i]:position()), v3(mods[j]:position())) end
end
local worstSpread = 0

world.every(1, function(t)
  local p = v3(front:position())
  print(string.format("t=%4.1f s  front x=%+.3f y=%+.3f z=%.3f  moved %.3f m", t, p[1], p[2], p[3], p[1] - start[1]))
  for i = 1, #mods do
    for j = i + 1, #mods do
      local d = math.abs(dist(v3(mods[i]:position()), v3(mods[j]:position())) - apart[i][j])
      worstSpread = math.max(worstSpread, d)
    end
  end
end)

world.at(10, function()
  local p = v3(front:position())
  local moved = p[1] - start[1]
  expect(moved > 0.3, string.format("the car drove forward %.3f m in 10 s, expected > 0.3", moved))
  expect(math.abs(p[2] - start[2]) < 0.05, string.format("it kept straight: %.3f m sideways", p[2] - start[2]))
  expect(math.abs(p[3] - start[3]) < 0.01, string.format("it stayed upright: chassis height %.3f m", p[3]))
  expect(worstSpread < 0.005, string.format("it stayed in one piece: distances between modules changed by %.4f m at most", worstSpread))
  for _, m in ipairs(mods) do expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error())) end
  atron.expect_connected(connections)
end)
