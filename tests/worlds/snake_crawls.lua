-- The 10-module SuperBot snake crawls at least 0.2 m forward in 10 s with the default settings,
-- and its docks stay closed (neighbouring dock faces within 1 mm).
world.set{duration = 10}
world.ground{friction = 0.8}
local chain = {}
for i = 1, 10 do
  chain[i] = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/snake.lua", params = {index = i - 1}})
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end
local x0 = chain[1]:position().x
local worstGap = 0
world.on_step(function()
  for i = 2, 10 do
    local a, b = chain[i - 1]:dock_position("back"), chain[i]:dock_position("front")
    local gap = math.sqrt((a.x - b.x) ^ 2 + (a.y - b.y) ^ 2 + (a.z - b.z) ^ 2)
    if gap > worstGap then worstGap = gap end
  end
end)
world.at(10, function()
  local moved = chain[1]:position().x - x0
  expect(moved >= 0.2, string.format("head moved %.3f m in 10 s, expected at least 0.2", moved))
  expect(worstGap < 0.001, string.format("dock gap reached %.4f m", worstGap))
  for i = 1, 10 do expect(chain[i]:error() == nil, "no module faulted") end
end)
