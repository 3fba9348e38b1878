-- The caterpillar's phases settle to the expected offsets: each module's pitch crosses zero
-- upwards lag/omega seconds after the module behind it (the counter passed down the chain set
-- its phase), and the chain moves forward.
world.set{duration = 10}
world.ground{friction = 0.8}
local n, period, lag = 8, 1.5, 2 * math.pi / 5
local chain = {}
for i = 1, n do
  chain[i] = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/caterpillar.lua"})
  if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
end
local x0 = chain[1]:position().x
local last, crossing = {}, {}
world.on_step(function(t)
  for i, m in ipairs(chain) do
    local a = m:joint_angle("pitch")
    if last[i] and last[i] < 0 and a >= 0 and t < 9 then crossing[i] = t end
    last[i] = a
  end
end)
world.at(9.5, function()
  for i = 1, n - 1 do
    -- module i (counter i-1) lags module i+1 by `lag`: it crosses later by lag/omega
    local dt = (crossing[i] - crossing[i + 1]) % period
    local phase = dt / period * 2 * math.pi
    expect(math.abs(phase - lag) < 0.25,
           string.format("modules %d and %d: phase offset %.2f rad, expected %.2f", i, i + 1, phase, lag))
  end
  expect(chain[1]:position().x - x0 > 0.2, "the chain moves forward")
end)
