-- A straight chain of 60 SuperBots built the obvious way (world.spawn + world.connect, every joint
-- at 0) running behaviors/snake.lua at friction 0.8: with the default start, the wave fades in
-- from the tail and is passed on towards the head one module every 0.1 s, and no connection
-- breaks. A second chain beside it starts everywhere at once (ramp_from = "all") and tears its
-- middle docks: getting shorter, each half slides against friction (mu W / 2, about 170 N here,
-- against the docks' 100 N). README "Long snakes" has the table for other lengths.
local n = 60
world.set{duration = 10}
world.ground{friction = 0.8}

local function chain(y, prefix, params)
  local c = {}
  for i = 1, n do
    local p = {index = i - 1}
    for k, v in pairs(params) do p[k] = v end
    c[i] = world.spawn("superbot", {at = {-(i - 1) * 0.19, y, 0.043}, name = prefix .. i,
                                    behavior = "behaviors/snake.lua", params = p})
    if i > 1 then world.connect(c[i - 1], "back", c[i], "front") end
  end
  return c
end
local tailFirst = chain(0, "t", {})
local together = chain(2, "a", {ramp_from = "all"})
local x0 = tailFirst[1]:position().x

-- The start travels from the tail: at 3 s the tail waves and the head has not begun.
local tailSwing, headSwing = 0, 0
world.on_step(function(t)
  if t > 2 and t <= 3 then
    tailSwing = math.max(tailSwing, math.abs(tailFirst[n]:joint_angle("pitch")))
    headSwing = math.max(headSwing, math.abs(tailFirst[1]:joint_angle("pitch")))
  end
end)

world.on_end(function(t)
  local side = {}
  for i = 1, n do side[tailFirst[i].id], side[together[i].id] = "t", "a" end
  local broken = {t = 0, a = 0}
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken[side[e.module_a]] = broken[side[e.module_a]] + 1 end
  end
  expect(tailSwing > 0.4, string.format("the tail's pitch swung %.3f rad between 2 and 3 s", tailSwing))
  expect(headSwing < 0.02, string.format("the head's pitch swung %.3f rad between 2 and 3 s", headSwing))
  expect(broken.t == 0, broken.t .. " connections of the tail-first chain broke")
  expect(broken.a > 0, "the chain started everywhere at once should tear (none broke)")
  local moved = tailFirst[1]:position().x - x0
  expect(moved > 0.1, string.format("the tail-first chain's head moved %.3f m", moved))
end)
