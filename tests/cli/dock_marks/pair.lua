-- Two SuperBots end to end, face to face: docked (world.connect) with --param docked=1, else
-- only touching, with the two touching docks disabled so they cannot latch. The pictures of the
-- two must differ by the engaged docks' marks (tests/cli/dock_marks_test.sh).
world.set{dt = 1 / 60, duration = 0.25}
world.ground{friction = 0.8}
local a = world.spawn("superbot", {at = {0, 0, 0.043}, name = "left"})
local b = world.spawn("superbot", {at = {-0.19, 0, 0.043}, name = "right"})
if tonumber(args.docked) == 1 then
  world.connect(a, "back", b, "front")
else
  a:set_dock("back", false)
  b:set_dock("front", false)
end
world.camera{eye = {-0.095, -0.55, 0.3}, target = {-0.095, 0, 0.05}, fov = 40}
