-- Rolling track (the paper's Fig. 1(e), section IV.B): six SuperBots docked front to back into a
-- closed loop that stands upright on the ground and rolls along it like a wheel or a tank track.
-- Every module runs behaviors/rolling_track.lua and knows only where it is round the loop, from
-- a noisy accelerometer percept (bottom / front / top / back, as an angle): it bends its pitch
-- joint so that the loop keeps the shape of an egg leaning forward, which keeps falling forward,
-- and measures from the same percept how fast it turns, to hold 2.5 rad/s (about 0.45 m/s).
-- The six modules spawn apart, bend to -60 deg, and at t = 2 s are docked into a hexagon by
-- world.connect; the last connect closes the loop between docks that already face each other
-- (lua/rolling_track_world.lua explains). Prints the progress every 2 s and checks at 20 s that
-- the loop rolled at least 0.5 m, stayed closed and standing, and that no module faulted.
-- Try: --param direction=-1 (roll the other way), --param rate=3.5, --param verbose=true.
local track = require("rolling_track_world")

-- The old "pgs" solver, 4 substeps x 60 iterations (its default 30 let the resting modules'
-- hinges sag enough that the loop missed world.connect's 1 mm / 1 deg). On the default "exact"
-- solver the loop's six servos, each bending to its own noisy reading, ask for shapes that do not
-- close: held exactly, they fight at full torque, the loop hops and its docks break at 2.6 s
-- (README, Joint solvers); pgs's softer joints absorb the misfit. Six modules still run ~15x
-- faster than real time.
world.set{dt = 1 / 60, duration = 20, solver = "pgs", solver_iterations = 60}
world.ground{friction = 0.8}

local loop = track.build{direction = args.direction, rate = args.rate, verbose = args.verbose}

world.every(2, function(t)
  if not loop.closed_at then return end
  local c = track.centroid(loop)
  print(string.format("t=%4.1f s  loop centre x=%+.3f m z=%.3f m  rolled %.3f m", t, c.x, c.z, track.moved(loop)))
end)

world.at(20, function() track.check(loop, 0.5) end)
