-- The Wheelbot's forward range sensor: Wheelbots at rest, each facing a static obstacle at a
-- known distance from its chassis front face (x = +0.10 in the module frame, where the sensor
-- sits). The raw reading, from the world (m:sensor) and from the behaviour (module.sensor), is
-- the true distance within 1 mm; past the 2 m maximum it reads nil; and percepts whose map
-- returns a table ({kind =, distance =, near =}), a string or a boolean reach the behaviour
-- intact (tests/behaviors/range_probe.lua checks them, errors on any mismatch, and disables its
-- "back" dock when 20 steps passed).
world.set{duration = 0.5}
world.ground{friction = 1.0}
local vec = require("vec")

local kFront = 0.10   -- the chassis front face, m ahead of the module origin
local cases = {
  {name = "box_0.40", distance = 0.40, shape = "box"},
  {name = "box_1.50", distance = 1.50, shape = "box"},
  {name = "box_1.99", distance = 1.99, shape = "box"},             -- just inside the 2 m maximum
  {name = "narrow_box_1.50", distance = 1.50, shape = "box", width = 0.1},  -- a 0.1 m box face
  {name = "cylinder_0.70", distance = 0.70, shape = "cylinder"},   -- a round face
  {name = "box_2.01", distance = 2.01, shape = "box", out = true}, -- just beyond: nil
  {name = "box_2.50", distance = 2.50, shape = "box", out = true},
  {name = "nothing", out = true},                                  -- no obstacle at all
}

for i, c in ipairs(cases) do
  local y = (i - 1) * 0.5
  local face = kFront + (c.distance or 0)
  if c.shape == "box" then
    c.body = world.box{size = {0.2, c.width or 0.3, 0.3}, at = {face + 0.1, y, 0.15}}
    c.truth = function(o, dir) return (face - o[1]) / dir[1] end  -- ray against the plane x = face
  elseif c.shape == "cylinder" then
    local r = 0.1
    c.body = world.cylinder{radius = r, length = 0.3, at = {face + r, y, 0.15}}
    c.truth = function(o, dir)  -- ray against the upright circle of radius r about (face + r, y)
      local dx, dy = o[1] - (face + r), o[2] - y
      local a, b = dir[1] ^ 2 + dir[2] ^ 2, 2 * (dx * dir[1] + dy * dir[2])
      local k = dx * dx + dy * dy - r * r
      return (-b - math.sqrt(b * b - 4 * a * k)) / (2 * a)
    end
  end
  c.m = world.spawn("wheelbot", {name = c.name, at = {0, y, 0.041}, behavior = "../behaviors/range_probe.lua",
                                 params = {distance = not c.out and c.distance}})
end

local checked = 0
world.on_step(function(t)
  if t < 0.1 then return end
  for _, c in ipairs(cases) do
    local reading = c.m:sensor("range:front")
    if c.out then
      if reading ~= nil then c.bad = c.bad or tostring(reading) end
    else
      -- the true distance from the sensor's actual pose (the module settles by a fraction of a mm)
      local p, q = vec.v3(c.m:position()), vec.q4(c.m:orientation())
      local o = vec.add(p, vec.qrot(q, {kFront, 0, 0}))
      local truth = c.truth(o, vec.qrot(q, {1, 0, 0}))
      local err = reading and math.abs(reading - truth) or math.huge
      if not c.worst or err > c.worst then c.worst, c.reading, c.true_d = err, reading, truth end
    end
  end
  checked = checked + 1
end)

world.at(0.5, function()
  expect(checked >= 20, "the world checked the readings for " .. checked .. " steps")
  for _, c in ipairs(cases) do
    if c.out then
      expect(c.bad == nil, string.format("%s: beyond 2 m should read nil, got %s", c.name, tostring(c.bad)))
    else
      expect(c.worst < 0.001, string.format("%s: reads %s m, true distance %.6f m (error %.2f mm, over 1 mm)",
                                            c.name, tostring(c.reading), c.true_d, 1000 * c.worst))
      expect(math.abs(c.true_d - c.distance) < 0.001, string.format("%s: the robot moved (true %.6f m)", c.name, c.true_d))
      print(string.format("%-16s largest error over %d steps %.4f mm", c.name, checked, 1000 * c.worst))
    end
    expect(c.m:error() == nil, c.name .. ": the behaviour's checks failed: " .. tostring(c.m:error()))
    if c.m:error() == nil then
      expect(c.m:dock_state("back").enabled == false, c.name .. ": the behaviour finished its checks (back dock disabled)")
    end
  end
end)
