-- A chain of SuperBots (six by default) whose modules coordinate only through dock messages,
-- driven from Python by worlds/python/distributed.py (behaviors/py_distributed.lua carries the
-- actions to the docks and the messages into the observations). Params: modules (default 6).
local n = args.modules or 6
world.set{dt = 1 / 60, duration = 10}
world.ground{friction = 0.8}
local chain = require("snake_chain").build{
  n = n, pose = "flat", behavior = "behaviors/py_distributed.lua", name = "m",
}
local x0 = chain[1]:position().x
world.on_step(function() world.metric("moved", chain[1]:position().x - x0) end)
