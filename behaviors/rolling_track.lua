-- Rolling track gait (the paper's Fig. 1(e), section IV.B): six SuperBots docked front to back in
-- a closed loop that stands upright on the ground roll along it like a wheel or a tank track,
-- each steered only by its own accelerometer. No module index, no position, no messages.
--
-- What a module perceives. In the loop every module's pitch axis is the loop's axle and its z
-- axis points into the loop, so gravity seen in the module's frame turns with its place round
-- the loop: lying at the bottom it reads (0, 0, +g), standing at the front end (front dock up)
-- (+g, 0, 0), upside down on top (0, 0, -g), at the back (-g, 0, 0). The percept `where` turns
-- that (noisy) reading into the module's angle round the loop, atan2(ax, az): 0 at the bottom,
-- +90 deg at the front, 180 deg on top, -90 deg at the back, and names the quarter ("bottom",
-- "front", "top", "back"); "front" is where the front docks of the bottom modules point. A
-- reading far from 1 g (a knock) is dropped and the last angle kept.
--
-- The gait. Each module bends its pitch joint, the hinge at its front end where the loop turns
-- to the next module, by
--     bend = 60 deg + lean * cos(2 * (joint - 135 deg)),   joint = angle + 30 deg
-- (joint: the angle round the loop of that hinge). Six 60 deg bends make a hexagon; the lean term
-- turns it into an egg leaning forward: hinges at the lower back and upper front bend more,
-- those at the lower front and upper back less. Such a shape's lowest point lies behind its
-- centre of mass, so gravity tips it forward. As the loop rolls, every module's angle changes
-- and it re-bends for its new place, so the leaning shape stays put in the world while the
-- modules flow round it like a tank track: the loop keeps falling forward.
--
-- Speed. A module also measures how fast its own angle advances (over the last `window`
-- seconds, from the same percept) and sets lean = gain * (rate - measured rate), within
-- +-max_lean: the full 30 deg from rest (a hexagon of 0.084 m square modules lies on a whole
-- module's flat side and needs some 25 deg to tip over its corner), less once the loop turns
-- near its rate, a backward lean (a brake) when too fast. Without it the loop accelerates until
-- the 3 rad/s joints cannot reshape it fast enough (0.8 to 0.9 m/s). It rolls face by face,
-- surging and now and then stalling on a face until the lean tips it again.

-- Forming. Until both its front and back docks are engaged (the world closes the loop), a module
-- holds pitch at -60 deg (front bracket turned towards its own +z) and roll and yaw at 0, with
-- an integral trim so that the six joint angles are right to a few hundredths of a degree and
-- the loop's last docks meet within world.connect's 1 mm and 1 deg. It starts rolling `settle`
-- seconds after its loop is closed.
--
-- params:
--   direction  1 (default): roll towards where the bottom modules' front docks point; -1: back
--   rate       loop turning rate to hold, rad/s (default 2.5: about 0.45 m/s for six modules,
--              whose loop is 1.14 m round)
--   max_lean   deg (default 30; bends stay within 30..90 deg, the joints' limits)
--   gain       lean in rad per rad/s of rate error (default 1)
--   window     seconds over which the rate is measured (default 1)
--   settle     seconds between closing the loop and rolling (default 0.5)
--   verbose    log the percept, rate and lean twice a second

local rolling = require("rolling_gait").new(params) -- the gait itself: lua/rolling_gait.lua

percepts = {where = rolling.percept}

function step(dt) rolling.step(dt) end
