-- Breakage: SuperBots hang in a vertical chain from a fixed one. Docks of this type give way at
-- 20 N. Two modules below a dock (about 14 N) hold; three (about 21 N) break it. The measured
-- load through the top dock is about the weight hanging below it.
world.set{duration = 1.5}
world.ground{}
local weak = "../modules/superbot_weak.lua"
local function hang(x, count)
  local top = world.spawn(weak, {at = {x, 0, 1.0}, fixed = true})
  local prev, prevDock = top, "down"
  local chain = {}
  for i = 1, count do
    chain[i] = world.spawn(weak, {at = {x, 0, 0.5}})
    world.connect(prev, prevDock, chain[i], "front")
    prev, prevDock = chain[i], "back"
  end
  return top, chain
end
local top2, two = hang(0, 2)
local top3, three = hang(1, 3)

local weight = 0.72 * 9.81
world.at(0.5, function()
  local load = top2:dock_load("down")
  expect(load ~= nil, "the two-module chain still hangs")
  if load then
    expect(math.abs(load.force - 2 * weight) < 0.15 * 2 * weight,
           string.format("top dock carries %.2f N, expected about %.2f N (two modules)", load.force, 2 * weight))
  end
  expect(not top3:dock_state("down").engaged, "three modules (about 21 N) broke the 20 N dock")
  expect(three[1]:position().z < 0.7, "the broken chain fell (it started at 0.85 m)")
end)
world.at(1.4, function()
  expect(top2:dock_state("down").engaged, "two modules (about 14 N) still hang at the end")
  local broken = 0
  for _, m in ipairs(three) do
    if m:dock_state("front").engaged == false and m == three[1] then broken = broken + 1 end
  end
  expect(broken == 1, "the first module of the three-chain was the one released")
end)
