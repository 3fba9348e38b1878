-- Snake: ten SuperBots docked front to back lie on the ground and crawl forward (+x) with a
-- vertical travelling wave on their pitch joints (behaviors/snake.lua). Prints the head's
-- progress every second and checks at the end that the chain moved and held together.
-- Try: --param modules=20, --param amplitude=0.8, --param joint=yaw (lateral undulation).

local n = args.modules or 10
world.set{dt = 1 / 60, duration = 10}
world.ground{friction = 0.8}

local chain = {}
for i = 1, n do
  chain[i] = world.spawn("superbot", {
    at = {-(i - 1) * 0.19, 0, 0.053},
    name = "snake_" .. i,
    behavior = "behaviors/snake.lua",
    params = {index = i - 1, joint = args.joint, amplitude = args.amplitude, period = args.period},
  })
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end

local head, tail = chain[1], chain[n]
local start = head:position()
world.every(1, function(t)
  local p = head:position()
  print(string.format("t=%4.1f s  head x=%+.3f m  moved %.3f m", t, p.x, p.x - start.x))
end)

world.at(10, function()
  local moved = head:position().x - start.x
  expect(moved > 0.2, string.format("the snake should crawl at least 0.2 m forward in 10 s, moved %.3f m", moved))
  local d = head:position().x - tail:position().x
  expect(d > (n - 1) * 0.19 * 0.8, "the chain should stay stretched out")
end)

-- Results for sweeps (`rm3d sweep`, README "Sweeps"): however long the run was.
world.on_end(function(t)
  if t <= 0 then return end
  world.metric("speed_m_s", (head:position().x - start.x) / t)
  world.metric("pieces", #world.components())
end)
