-- Limits hold: a servo target beyond the +-90 degree limit stops at the limit, and a velocity
-- drive pushing into the limit for 2 s does not pass it by more than 2 degrees.
world.set{duration = 3}
world.ground{}
local servo = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/hold.lua",
                                       params = {targets = {roll = 3.0, pitch = -3.0}}})
local drive = world.spawn("superbot", {at = {0, 0.5, 0.043}, behavior = "behaviors/hold.lua",
                                       params = {velocities = {yaw = 3.0, roll = -3.0}}})
local worst = 0
world.on_step(function()
  for _, m in ipairs({servo, drive}) do
    for name, a in pairs(m:joint_angles()) do
      worst = math.max(worst, math.abs(math.deg(a)) - 90)
    end
  end
end)
world.at(2.5, function()
  expect(worst < 2, string.format("a joint passed its limit by %.2f deg", worst))
  expect(math.deg(servo:joint_angle("roll")) > 88, "servo roll should rest at the +90 limit")
  expect(math.deg(servo:joint_angle("pitch")) < -88, "servo pitch should rest at the -90 limit")
  expect(math.deg(drive:joint_angle("yaw")) > 87, "velocity-driven yaw should be pressed against +90")
  expect(math.deg(drive:joint_angle("roll")) < -87, "velocity-driven roll should be pressed against -90")
end)
