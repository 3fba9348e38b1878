-- Two Wheelbots roam a walled 3 x 3 m arena with boxes and cylinders in it for a minute, each
-- avoiding obstacles, walls and the other robot with behaviors/wheelbot_avoid.lua: it sees only
-- through its forward range sensor, read with gaussian noise (1 cm) and 5% dropouts, and drives
-- its wheels through noisy commands (0.1 rad/s).
--
-- The checks (over the whole minute, from the world's side, which reads the raw sensors):
--   * no chassis ever touches anything: each robot's `contact:chassis` sensor is read after
--     every step and must never be true (the wheels touch the floor, the chassis does not; the
--     wheels stick out 1 cm ahead of and 2.5 cm beside the chassis, so a glancing wheel is allowed);
--   * each robot kept moving: its path (the sum of its step-by-step horizontal displacements)
--     is at least 3 m;
--   * each stayed inside the arena and upright, and no behaviour faulted.
--
--   ./build/rm3d run worlds/wheelbot.lua --png out/wheelbot.png [--seed N] [--param speed=8]
--
-- Over seeds 1-200 both robots kept clear in every run (one robot alone: seeds 1-100 likewise).
world.set{duration = 60, seed = 1}
world.ground{friction = 1.0}

-- Walls: a 3 x 3 m inside, 0.1 m thick, 0.25 m high (static: no mass).
local kHalf, kWall, kH = 1.5, 0.1, 0.25
world.box{size = {2 * kHalf + 2 * kWall, kWall, kH}, at = {0, kHalf + kWall / 2, kH / 2}}
world.box{size = {2 * kHalf + 2 * kWall, kWall, kH}, at = {0, -kHalf - kWall / 2, kH / 2}}
world.box{size = {kWall, 2 * kHalf, kH}, at = {kHalf + kWall / 2, 0, kH / 2}}
world.box{size = {kWall, 2 * kHalf, kH}, at = {-kHalf - kWall / 2, 0, kH / 2}}

-- Obstacles: boxes (one turned, one a thin slab at an angle, one filling a corner) and upright
-- cylinders, with gaps of 0.4 m or more between them and to the walls.
world.box{size = {0.4, 0.4, 0.2}, at = {0.5, 0.5, 0.1}, rot = {0, 0, 0.4}}
world.box{size = {0.6, 0.1, 0.2}, at = {-0.7, 0.75, 0.1}, rot = {0, 0, 0.8}}
world.box{size = {0.4, 0.4, 0.15}, at = {1.3, -1.3, 0.075}}
world.cylinder{radius = 0.12, length = 0.3, at = {-0.6, -0.6, 0.15}}
world.cylinder{radius = 0.08, length = 0.3, at = {0.55, -0.45, 0.15}}
world.cylinder{radius = 0.15, length = 0.2, at = {-0.1, -0.1, 0.1}}

-- --param speed=8, safe=, width=, ... reach the behaviour (see its header); --param bots=1 runs one.
local params = {}
for _, k in ipairs{"debug", "speed", "safe", "width", "turn_speed", "scan", "max_leg", "horizon", "memory"} do
  params[k] = args[k]
end
local bots = {
  world.spawn("wheelbot", {name = "wheelbot_a", at = {-1.1, -1.1, 0.041}, rot = {0, 0, 0.3},
                           behavior = "behaviors/wheelbot_avoid.lua", params = params}),
}
if (args.bots or 2) > 1 then
  bots[2] = world.spawn("wheelbot", {name = "wheelbot_b", at = {1.1, 1.1, 0.041}, rot = {0, 0, math.pi + 0.3},
                                     behavior = "behaviors/wheelbot_avoid.lua", params = params})
end
world.camera{eye = {0, -2.55, 2.75}, target = {0, -0.05, 0}}

local path, last, touched, inside, upright = {}, {}, {}, {}, {}
for i, m in ipairs(bots) do
  path[i], last[i], touched[i], inside[i], upright[i] = 0, m:position(), nil, true, true
end

world.on_step(function(t)
  for i, m in ipairs(bots) do
    local p = m:position()
    path[i] = path[i] + math.sqrt((p.x - last[i].x) ^ 2 + (p.y - last[i].y) ^ 2)
    last[i] = p
    if m:sensor("contact:chassis") and not touched[i] then
      touched[i] = string.format("t=%.3f at (%.3f, %.3f)", t, p.x, p.y)
    end
    if math.abs(p.x) > kHalf or math.abs(p.y) > kHalf then inside[i] = false end
    local q = m:orientation()
    if 1 - 2 * (q.x * q.x + q.y * q.y) < 0.9 then upright[i] = false end  -- body z tilted > 25 deg
  end
end)

world.every(10, function(t)
  for i, m in ipairs(bots) do
    local p = m:position()
    print(string.format("t=%4.1f s  %s at (%+.2f, %+.2f)  path %.2f m", t, m.name, p.x, p.y, path[i]))
  end
end)

world.at(60, function()
  for i, m in ipairs(bots) do
    expect(touched[i] == nil, m.name .. "'s chassis touched something: " .. tostring(touched[i]))
    expect(path[i] >= 3, string.format("%s should drive at least 3 m in the minute, drove %.2f m", m.name, path[i]))
    expect(inside[i], m.name .. " stayed inside the arena")
    expect(upright[i], m.name .. " stayed upright")
    expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error()))
  end
end)
