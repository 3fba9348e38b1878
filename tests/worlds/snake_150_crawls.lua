-- A 150-module SuperBot snake, started in its gait's pose (lua/snake_chain.lua), crawls 10 s at
-- the world's defaults (the exact solver, 1 substep of 15 iterations) with friction 0.8 and
-- breaks nothing (measured: largest dock load 79.7 N, head 1.13 m; at 2 substeps x 10, 65.1 N and
-- 1.13 m; before contacts were swept until settled after a motor saturates, 62 N and 1.17 m): no
-- dock reaches the SuperBot's 100 N / 10 N m, its hinges stay closed, and it moves forward.
-- Started straight, the chain must shorten against friction and its middle docks break; put down
-- tilted (levelled head to tail instead of on its troughs), its raised end falls and 21 break.
local n = 150
world.set{duration = 10}
world.ground{friction = 0.8}
local chain = require("snake_chain").build{n = n, behavior = "behaviors/snake.lua"}

-- Every trough is on the ground at the start: the lowest module frame of each wavelength (five
-- modules) is within 2 mm of the lowest of all.
local low, lows = math.huge, {}
for i = 1, n do
  local z = chain[i]:position().z
  local w = (i - 1) // 5 + 1
  lows[w] = math.min(lows[w] or math.huge, z)
  low = math.min(low, z)
end
local worstTrough = 0
for w = 2, #lows - 1 do worstTrough = math.max(worstTrough, lows[w] - low) end
expect(worstTrough < 0.002, string.format("a trough starts %.4f m above the lowest", worstTrough))

local x0 = chain[1]:position().x
local maxLoad, worstGap = 0, 0
world.every(0.1, function()
  for i = 1, n - 1 do
    local l = chain[i]:dock_load("back")
    if l then maxLoad = math.max(maxLoad, l.force) end
    local a, b = chain[i]:dock_position("back"), chain[i + 1]:dock_position("front")
    worstGap = math.max(worstGap, math.sqrt((a.x - b.x) ^ 2 + (a.y - b.y) ^ 2 + (a.z - b.z) ^ 2))
  end
end)
world.at(10, function()
  local broken = 0
  for _, e in ipairs(world.events()) do if e.event == "broken" then broken = broken + 1 end end
  expect(broken == 0, broken .. " connections broke")
  expect(#world.components() == 1, "the chain is in " .. #world.components() .. " pieces")
  expect(maxLoad < 90, string.format("largest dock load %.1f N", maxLoad))
  expect(worstGap < 0.001, string.format("dock faces %.4f m apart", worstGap))
  local moved = chain[1]:position().x - x0
  expect(moved > 0.8, string.format("head moved %.3f m in 10 s, expected over 0.8", moved))
end)
