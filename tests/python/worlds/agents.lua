-- A chain of SuperBots for the Python API's tests (tests/python): each module runs
-- agent.lua (observe() and act(a)); the world gives a reward per module (its x speed) and says
-- done once the head has passed args.goal metres.
local n = args.modules or 4
world.set{dt = 1 / 60, duration = args.duration or 5, seed = 7}
world.ground{friction = 0.8}
local chain = require("snake_chain").build{n = n, behavior = "agent.lua", pose = "flat",
                                           params = {hops = args.hops or 0}}
local head = chain[1]
local last = {}
for i, m in ipairs(chain) do last[i] = m:position().x end
world.reward(function(t)
  local r = {}
  for i, m in ipairs(chain) do
    local x = m:position().x
    r[i] = (x - last[i]) / world.dt()
    last[i] = x
  end
  return r
end)
local goal = args.goal or 1e9
world.done(function(t) return head:position().x > goal end)
world.on_end(function(t) world.metric("head_x", head:position().x) end)
