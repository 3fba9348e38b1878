-- The scene of the golden-image test (tests/engine/render/golden_image_test.cpp): a SuperBot
-- with its pitch bent, an ATRON and a box on the ground, seen from a fixed camera. As a test
-- world it only checks that the pose it is rendered in is reached.
world.set{duration = 1}
world.ground{}
world.camera{eye = {0.32, -0.42, 0.28}, target = {-0.02, 0.06, 0.04}}
local s = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "behaviors/hold.lua",
                                   params = {targets = {pitch = 0.6}}})
world.spawn("atron", {at = {0.1, 0.25, 0.056}})
world.box{size = {0.08, 0.08, 0.08}, at = {-0.2, 0.2, 0.04}}
world.at(1, function()
  expect(math.abs(s:joint_angle("pitch") - 0.6) < 0.02, "pitch reached 0.6 rad")
end)
