-- The six-SuperBot rolling track (worlds/rolling_track.lua, behaviors/rolling_track.lua) as a
-- test, built by the same lua/rolling_track_world.lua: two loops 4 m apart, one rolling forward
-- (+x, direction 1) and one backward (direction -1). Each is docked by world.connect at 2 s, the
-- last connect closing it between docks that already face each other, and at 20 s each must
-- have rolled at least 0.5 m its way, kept all six docks engaged throughout, still stand, and
-- have no faulted module.
local track = require("rolling_track_world")
-- On the old "pgs" solver, as worlds/rolling_track.lua explains (the loop's servos fight on "exact").
world.set{dt = 1 / 60, duration = 20, solver = "pgs", solver_iterations = 60}
world.ground{friction = 0.8}
local forward = track.build{at = {0, 0}, name = "forward", direction = 1}
local backward = track.build{at = {0, 4}, name = "backward", direction = -1}
world.at(20, function()
  track.check(forward, 0.5)
  track.check(backward, 0.5)
  print(string.format("rolled %.2f m forward and %.2f m backward", track.moved(forward), track.moved(backward)))
end)
