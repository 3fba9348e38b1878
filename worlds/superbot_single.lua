-- One SuperBot on the ground sweeping each of its joints in turn (pitch, then roll, then yaw)
-- through +-60 degrees: shows the three joint axes and the servo tracking. Prints the angles
-- every half second and checks that each joint follows its target.

world.set{dt = 1 / 60, duration = 6}
world.ground{}
local m = world.spawn("superbot", {at = {0, 0, 0.043}, name = "sweeper", behavior = "behaviors/sweep.lua",
                                   params = {amplitude = math.rad(60), period = 2}})

world.every(0.5, function(t)
  local a = m:joint_angles()
  print(string.format("t=%.1f  pitch=%+6.1f  roll=%+6.1f  yaw=%+6.1f deg", t, math.deg(a.pitch), math.deg(a.roll),
                      math.deg(a.yaw)))
end)

-- Each joint peaks at +60 degrees half way through its 2 s slot.
for k, name in ipairs({"pitch", "roll", "yaw"}) do
  world.at((k - 1) * 2 + 0.5 + 0.25, function()
    local deg = math.deg(m:joint_angle(name))
    expect(deg > 45, string.format("%s should swing towards +60 deg, is at %.1f", name, deg))
  end)
end
