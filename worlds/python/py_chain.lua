-- A straight chain of SuperBots (seven by default) whose pitch joints are driven from Python:
-- the world of worlds/python/train_chain.py and of the Gym/PettingZoo wrappers' tests
-- (docs/python.md). Each module runs behaviors/py_chain.lua (obs: pitch angle and velocity;
-- act: the pitch target). Every module's reward is how far the chain's mean x moved in the last
-- step (m), so an episode's return is the distance crawled along +x.
-- Params: modules (default 7), seconds (the duration, default 10), done_after (seconds: every
-- module is done from then on; default never), behavior (default behaviors/py_chain.lua;
-- behaviors/snake.lua runs the same chain with the Lua gait, as tests/python/bench.py does).
local n = args.modules or 7
world.set{dt = 1 / 60, duration = args.seconds or 10}
world.ground{friction = 0.8}

local chain = require("snake_chain").build{
  n = n, pose = "flat", behavior = args.behavior or "behaviors/py_chain.lua", name = "m",
}

local function meanX()
  local s = 0
  for _, m in ipairs(chain) do s = s + m:position().x end
  return s / #chain
end

local x0 = meanX()
local last, gain = x0, 0
world.on_step(function()
  local x = meanX()
  gain, last = x - last, x
  world.metric("moved", x - x0)
end)
world.metric("moved", 0)
world.reward(function() return gain end)

local doneAfter = args.done_after
if doneAfter then
  world.done(function() return world.time() >= doneAfter end)
end
