-- Two ATRON cars couple at run time and part again (the paper's Fig. 5, bottom).
--
-- A `tug` (the 7-module car of worlds/atron_car.lua plus a hitch) drives +x and a `car` (the
-- same 7-module car, mirrored) drives -x towards it. They meet nose to nose: the tug's hitch
-- docks to the hubs of the car's front wheels through the ATRON docks at run time (the magnet
-- pulls the faces together and latches them; nothing here calls world.connect between the
-- two cars), and the two become one 15-module vehicle. That vehicle drives on +x, the car's
-- wheels now turning backwards with the tug's. Three seconds later the tug lets go: its hitch
-- disables the docks that hold the car, and the tug backs away on its own while the car brakes.
--
--   hitch    In the lattice the front wheels stand a step ahead of the chassis, so two of these
--            cars meet wheel to wheel: their chassis are two steps apart, and no pair of
--            facing docks of one car and the other can come together by driving straight at
--            each other (tried for every placement on the ground: only the outer, spinning
--            hemispheres of wheels passing side by side ever face each other). One more ATRON,
--            `tug_hitch`, a lattice step ahead of the tug's front wheels at chassis height and
--            docked to both their hubs (inner hemispheres, which do not turn), reaches the site
--            where the car's front wheel hubs face it. So the hitch docks twice: to car_wheel_1
--            and car_wheel_2 (one male-female pair each, as the lattice rule promises). Both
--            cars are built on one ATRON lattice (assets/modules/atron.lua), the car four lattice
--            units plus `gap` further along x, so driving straight brings the docks face to face.
--   protocol behaviors/atron_coupling.lua on every module: a dock that engages at run time says
--            hello with its car's name; a hello from the other car floods "coupled" through the
--            joined vehicle (the car's wheels reverse); `release_after` seconds later the hitch
--            floods "release" (the tug reverses, the car brakes) and one step after that
--            disables its foreign docks, which ends the connections in that step.
--   speeds   wheels at 1 rad/s, 0.039 m/s each (see worlds/atron_car.lua): the cars close at
--            0.078 m/s, 1.3 mm a step, so the faces step into the 4 mm latch distance (4.3 mm,
--            then 2.9 mm; the hulls would touch at about 2.8 mm) and latch in the next step, at
--            full speed. Each hitch connection peaks as it latches, up to about 58 N and 6.2 N m
--            (dock strength 100 N, 10 N m); at 10 substeps x 100 iterations the meeting's impact
--            breaks the hitch, and met slowly the joined vehicle's eight speed-driven wheels,
--            fighting through its frame, break it 0.6 s after coupling (docs/benchmarks.md,
--            "Larger trees on their own operator").
--
-- Timeline with the defaults: coupled at t = 2.00 s, released at 5.05 s, and by t = 9 s the tug is
-- 0.154 m further from the car than at the release (the car has not moved).
-- The checks: separate cars at the start; one component while coupled, joined through at least one
-- connection made at run time between a tug module and a car module, and moving as one (both
-- fronts +x by the same distance); two components again after the release, the same two cars; the
-- tug backed away (its distance from the car grows by more than 0.1 m) while the car stayed; no
-- connection broke; no module faulted.
--
--   ./build/rm3d run worlds/atron_cars.lua --png out/atron_cars.png
--   ./build/rm3d run worlds/atron_cars.lua --seconds 3.5 --png out/atron_cars_coupled.png
--   options: --param gap=0.15 (m, initial dock gap)  --param hold=3 (s coupled)
local kGap = args.gap or 0.15    -- initial gap between the docks that will couple, m
local kHold = args.hold or 3     -- seconds coupled before the tug lets go
local kSpeed = 0.039             -- m/s, one car's speed (wheels at 1 rad/s)
local kDuration = math.ceil(kGap / (2 * kSpeed) + kHold + 4)  -- 9 s with the defaults
world.set{duration = kDuration}
world.ground{friction = 1.0}

local kR = 0.056                 -- a wheel's centre height: radius 0.055 + the 1 mm hull margin
local kA = 0.11 / math.sqrt(2)   -- lattice unit: neighbours' centres differ by two steps of kA
local kH = math.sqrt(0.5)
local kDocks = require("atron").docks
local kMale = require("atron").male
local kBehavior = "behaviors/atron_coupling.lua"

local vec = require("vec")
local atron = require("atron")
local v3, dot, dist, qmul, qrot = vec.v3, vec.dot, vec.dist, vec.qmul, vec.qrot
local dockToward, outerPole = atron.dock_toward, atron.outer_pole

-- Connections made here with world.connect, by "id:dock" of either end.
local made = {}
local function connect(a, da, b, db)
  world.connect(a, da, b, db)
  made[a.id .. ":" .. da] = true
  made[b.id .. ":" .. db] = true
end

-- A car as in worlds/atron_car.lua heading +x (h = 1), or its mirror image heading -x (h = -1).
-- Both fronts get the same orientation, so the two cars lie on one lattice. wheelParams(plusX)
-- gets the equator speed sign that rolls that wheel towards +x.
local axisX = {0.5, 0.5, 0.5, 0.5}
local tilt = {math.cos(math.pi / 8), math.sin(math.pi / 8), 0, 0}
local function buildCar(name, x, h, wheelParams, chassisParams)
  local c = {modules = {}}
  local function spawn(mname, opts)
    opts.name, opts.behavior = mname, kBehavior
    local m = world.spawn("atron", opts)
    c.modules[#c.modules + 1] = m
    return m
  end
  local function attach(a, dir, mname, wheel)
    local da = dockToward(a, dir)
    local params = wheel and wheelParams(dot(outerPole(a, da), {0, 1, 0}) > 0 and -1 or 1) or chassisParams()
    local b = spawn(mname, {params = params})
    connect(a, da, b, kMale[da] and "s1" or "s0")
    return b
  end
  c.front = spawn(name .. "_front", {at = {x, 0, kR + kA * kH + 0.0005}, quat = qmul(tilt, axisX),
                                     params = chassisParams()})
  local middle = attach(c.front, {-h, kH, kH}, name .. "_middle")
  local rear = attach(middle, {-h, -kH, -kH}, name .. "_rear")
  c.wheel1 = attach(c.front, {h, kH, -kH}, name .. "_wheel_1", true)
  c.wheel2 = attach(c.front, {h, -kH, -kH}, name .. "_wheel_2", true)
  attach(rear, {-h, kH, -kH}, name .. "_wheel_3", true)
  attach(rear, {-h, -kH, -kH}, name .. "_wheel_4", true)
  c.spawn = spawn
  return c
end

-- The tug: forward (+x) alone and coupled, backwards after the release.
local tug = buildCar("tug", 0, 1,
  function(plusX) return {car = "tug", solo = plusX, coupled = plusX, released = -plusX} end,
  function() return {car = "tug"} end)
-- Its hitch, a lattice step ahead of the front wheels (2 kA ahead of the front, at its height),
-- docked to both wheel hubs; it orders the release and is the one that lets go.
local hitch = tug.spawn("tug_hitch", {params = {car = "tug", lead = true, leaves = true, release_after = kHold}})
local toHitch1 = dockToward(tug.wheel1, {1, -kH, kH})
connect(tug.wheel1, toHitch1, hitch, kMale[toHitch1] and "s1" or "s0")
connect(tug.wheel2, dockToward(tug.wheel2, {1, kH, kH}), hitch, dockToward(hitch, {-1, -kH, -kH}))

-- The car: heads -x towards the tug, the docks of its front wheel hubs `gap` (along x) from the
-- hitch's; when coupled its wheels roll with the tug's (+x); after the release it brakes.
local car = buildCar("car", 4 * kA + kGap, -1,
  function(plusX) return {car = "car", solo = -plusX, coupled = plusX, released = "brake"} end,
  function() return {car = "car"} end)

local inTug = {}
for _, m in ipairs(tug.modules) do inTug[m.id] = true end

-- The connection graph now: connections as {a, da, b, db} (ids and dock names), from world.graph.
local function connections()
  local json = world.graph("json")
  local list = json:match('"connections"%s*:%s*(%b[])')
  local out = {}
  for a, da, b, db in list:gmatch('%[%s*(%d+)%s*,%s*"([%w_]+)"%s*,%s*(%d+)%s*,%s*"([%w_]+)"%s*%]') do
    out[#out + 1] = {tonumber(a), da, tonumber(b), db}
  end
  return out
end
-- Connections between the two cars, and how many of them world.connect did not make.
local function joints()
  local between, runtime = 0, 0
  for _, c in ipairs(connections()) do
    if inTug[c[1]] ~= inTug[c[3]] then
      between = between + 1
      if not (made[c[1] .. ":" .. c[2]] or made[c[3] .. ":" .. c[4]]) then runtime = runtime + 1 end
    end
  end
  return between, runtime
end
-- True when the components are exactly the two cars.
local function twoCars()
  local comps = world.components()
  if #comps ~= 2 then return false end
  for _, comp in ipairs(comps) do
    local side = inTug[comp[1].id]
    for _, m in ipairs(comp) do if inTug[m.id] ~= side then return false end end
  end
  return true
end

local nMade = 0
for _ in pairs(made) do nMade = nMade + 1 end
expect(twoCars(), "the tug and the car start as two separate components")
expect(select(1, joints()) == 0, "no connection between the cars at the start")
print(string.format("tug: %d modules, car: %d modules, %d connections made with world.connect",
                    #tug.modules, #car.modules, nMade // 2))
world.camera{eye = {0.15, -0.75, 0.45}, target = {0.3, 0, 0.06}}

local function x(m) return m:position().x end
local function gapNow() return dist(v3(hitch:position()), v3(car.front:position())) end
local coupledAt, releasedAt, coupledCheckDone
local atCoupling, atRelease = {}, {}
world.on_step(function(t)
  local n = #world.components()
  if not coupledAt and n == 1 then
    coupledAt = t
    atCoupling = {tug = x(tug.front), car = x(car.front)}
    local between, runtime = joints()
    print(string.format("coupled at t=%.3f s: one component, %d connections between the cars, %d of them made at run time",
                        t, between, runtime))
  elseif coupledAt and not releasedAt and n == 2 then
    releasedAt = t
    atRelease = {gap = gapNow(), tug = x(tug.front), car = x(car.front)}
    print(string.format("released at t=%.3f s: two components; coupled, the vehicle drove %+.3f m (tug) %+.3f m (car)",
                        t, atRelease.tug - atCoupling.tug, atRelease.car - atCoupling.car))
  end
  -- Half a second into the coupled phase: one vehicle, joined at run time.
  if coupledAt and not coupledCheckDone and t >= coupledAt + 0.5 then
    coupledCheckDone = true
    local between, runtime = joints()
    expect(#world.components() == 1, "coupled: one component")
    expect(runtime >= 1 and runtime == between,
           string.format("coupled through connections made at run time: %d of %d", runtime, between))
  end
end)

world.every(1, function(t)
  print(string.format("t=%4.1f s  components %d  tug front x=%+.3f  car front x=%+.3f  hitch-car %.3f m",
                      t, #world.components(), x(tug.front), x(car.front), gapNow()))
end)

world.at(kDuration, function()
  expect(coupledAt ~= nil and coupledAt < kGap / (2 * kSpeed) + 0.5,
         "the cars coupled when their docks met, at t=" .. tostring(coupledAt))
  expect(releasedAt ~= nil and coupledAt ~= nil and releasedAt > coupledAt + 0.5 * kHold,
         "they came apart only after the coupled phase, at " .. tostring(releasedAt))
  if coupledAt and releasedAt then
    local dTug, dCar = atRelease.tug - atCoupling.tug, atRelease.car - atCoupling.car
    expect(dTug > 0.06 and math.abs(dTug - dCar) < 0.003,
           string.format("coupled, they drove as one vehicle: tug %+.3f m, car %+.3f m", dTug, dCar))
    local grew = gapNow() - atRelease.gap
    expect(grew > 0.1, string.format("the tug drove away: its distance from the car grew by %.3f m", grew))
    expect(x(tug.front) < atRelease.tug - 0.1 and math.abs(x(car.front) - atRelease.car) < 0.01,
           string.format("the tug backed off %.3f m; the car stayed (%+.3f m)",
                         atRelease.tug - x(tug.front), x(car.front) - atRelease.car))
  end
  expect(twoCars(), "at the end: two components again, the tug and the car")
  expect(select(1, joints()) == 0, "no connection left between the cars")
  -- Every connection made with world.connect still holds (none broke).
  for _, c in ipairs(connections()) do made[c[1] .. ":" .. c[2]] = nil; made[c[3] .. ":" .. c[4]] = nil end
  expect(next(made) == nil, "every connection made with world.connect still holds")
  for _, m in ipairs(world.modules()) do expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error())) end
end)
