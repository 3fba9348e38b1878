-- A 150-module SuperBot snake started in its gait's pose (lua/snake_chain.lua) crawls 3 s on the
-- old "pgs" solver at its defaults (4 substeps of 30 iterations) with friction 0.8 and breaks
-- nothing (measured: 0.38 m, at most 37 N); tests/worlds/snake_150_crawls.lua runs it 10 s at the
-- world's defaults (the exact solver).
local n = 150
world.set{duration = 3, solver = "pgs"}
world.ground{friction = 0.8}
local chain = require("snake_chain").build{n = n, behavior = "behaviors/snake.lua"}
local x0 = chain[1]:position().x
local maxLoad = 0
world.every(0.1, function()
  for i = 1, n - 1 do
    local l = chain[i]:dock_load("back")
    if l then maxLoad = math.max(maxLoad, l.force) end
  end
end)
world.at(3, function()
  local broken = 0
  for _, e in ipairs(world.events()) do if e.event == "broken" then broken = broken + 1 end end
  expect(broken == 0, broken .. " connections broke")
  expect(#world.components() == 1, "the chain is in " .. #world.components() .. " pieces")
  expect(maxLoad < 70, string.format("largest dock load %.1f N", maxLoad))
  local moved = chain[1]:position().x - x0
  log(string.format("head moved %.3f m, largest dock load %.1f N", moved, maxLoad))
  expect(moved > 0.25, string.format("head moved %.3f m in 3 s, expected over 0.25", moved))
end)
