-- Snake: SuperBots docked front to back (ten by default) lie on the ground and crawl forward (+x)
-- with a travelling wave on their pitch joints (behaviors/snake.lua). Prints the head's progress
-- every second and checks at the end that the chain moved and held together.
-- Try: --param modules=150 (or up to 1000, the paper's scale experiment), --param amplitude=0.8,
-- --param joint=yaw (lateral undulation).
--
-- The chain is built in its wave's own pose and put down on its troughs (lua/snake_chain.lua), so
-- it never has to get shorter against friction as the wave starts: a straight chain of 150 would
-- tear its middle docks (README, "Long snakes").

local n = args.modules or 10
local joint = args.joint or "pitch"
world.set{dt = 1 / 60, duration = 10}
world.ground{friction = 0.8}

local chain = require("snake_chain").build{
  n = n, joint = joint, amplitude = args.amplitude, period = args.period,
  behavior = "behaviors/snake.lua",
}
n = #chain

local head, tail = chain[1], chain[n]
local start = head:position()
local length0 = math.abs(start.x - tail:position().x)
world.every(1, function(t)
  local p = head:position()
  print(string.format("t=%4.1f s  head x=%+.3f m  moved %.3f m", t, p.x, p.x - start.x))
end)

-- The checks run however long the run was (--seconds, --steps).
world.on_end(function(t)
  if t <= 0 then return end
  local moved = head:position().x - start.x
  local broken = 0
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken = broken + 1 end
  end
  local pieces = #world.components()
  expect(broken == 0, string.format("%d of %d connections broke", broken, n - 1))
  expect(pieces == 1, string.format("the chain is in %d pieces", pieces))
  -- The vertical wave crawls about 10 cm/s; expect at least 2 cm/s once it has run a second.
  if joint == "pitch" and t >= 1 then
    expect(moved > 0.02 * t, string.format("the snake should crawl at least %.2f m forward in %.1f s, moved %.3f m",
                                           0.02 * t, t, moved))
  end
  local d = math.abs(head:position().x - tail:position().x)
  expect(d > 0.8 * length0, string.format("the chain should stay stretched out: head to tail %.3f m, was %.3f m", d, length0))
  -- Results for sweeps (`rm3d sweep`, README "Sweeps").
  world.metric("speed_m_s", moved / t)
  world.metric("pieces", pieces)
  world.metric("broken", broken)
end)
