-- A position servo reaches a 45 degree target within 2 degrees in 1 s, on each joint.
world.set{duration = 1.2}
world.ground{}
local mods = {}
for k, j in ipairs({"pitch", "roll", "yaw"}) do
  mods[j] = world.spawn("superbot", {at = {0, k * 0.5, 0.043}, behavior = "behaviors/hold.lua",
                                     params = {targets = {[j] = math.rad(45)}}})
end
world.at(1.0, function()
  for j, m in pairs(mods) do
    local deg = math.deg(m:joint_angle(j))
    expect(math.abs(deg - 45) < 2, string.format("%s at %.2f deg after 1 s, expected 45 +- 2", j, deg))
  end
end)
