-- Caterpillar: ten SuperBots docked in a chain find their place in it by messages (the head
-- counts 0 and each module forwards its count + 1 down the chain, one step per hop) and crawl
-- with the travelling wave those counts give (behaviors/caterpillar.lua). Unlike snake.lua, the
-- world tells no module its index.
world.set{duration = 10}
world.ground{friction = 0.8}
local chain = {}
for i = 1, 10 do
  chain[i] = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/caterpillar.lua"})
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end
local x0 = chain[1]:position().x
world.every(2, function(t)
  print(string.format("t=%4.1f s  head moved %.3f m", t, chain[1]:position().x - x0))
end)
world.at(10, function()
  expect(chain[1]:position().x - x0 > 0.2, "the caterpillar crawls forward")
end)
