-- A trotting gait for a chain with one-module legs on its side docks (the walker that
-- lua/lay_retrieve.lua builds): each leg's pitch joint (its hip, about the body's long axis)
-- stands the body up on the feet and lifts the foot, and its yaw joint (at the foot) swings the
-- foot forward in the air and back on the ground. Diagonal legs move together: the front left
-- and the rear right, then the front right and the rear left.
--
-- Each leg steers by itself: it reads the body's heading from its own orientation (a leg lies
-- across the body, so its own heading is the body's turned a quarter) and lengthens the strides
-- on the side that lags. Without it, the 8-module walker turned left 18 deg in 0.5 m: its two
-- sides are not mirror images (the yaw joint sits on the back bracket, turned a quarter from the
-- front one), and at 5 per radian it keeps within 2 deg.
--
--   local gait = require("walker_gait")
--   local pitch, yaw = gait.leg(t - t0, "left", 0, headingError)
--
-- Measured (2026-11-30) at dt 1/60: the 8-module walker of worlds/snake_walker_snake.lua walks
-- 0.518 m in 22.3 s, 2 s of it standing up (one substep; 0.51 m in 19.3 s at two); built
-- directly, 0.61 m in 19 s with its heading within 1.6 deg and its body 10 cm up (5.6 cm clear of
-- the ground; two substeps).
local M = {
  period = 2.0,   -- s a stride
  stand = 0.5,    -- rad of hip: the feet down, the body up
  lift = -0.6,    -- rad of hip added at the middle of a swing
  swing = 0.5,    -- rad of foot each way
  duty = 0.5,     -- share of the stride in the air
  steer = 5,      -- stride change per radian of heading error
  rise = 2.0,     -- s to stand up before the first stride
}

--- The hip (pitch) and foot (yaw) targets of a leg at time t since the gait began, on `side`
--- ("left" or "right") of the body, with `phase` (0 or 0.5: the diagonal pair), when the body's
--- heading is `err` radians to the left of where it was at the start.
function M.leg(t, side, phase, err)
  if t < M.rise then return M.stand * math.max(0, t) / M.rise, 0 end
  local s = side == "right" and 1 or -1
  local stride = M.swing * math.max(0, math.min(2, 1 - s * M.steer * err))
  local u = ((t - M.rise) / M.period + phase) % 1
  if u < M.duty then
    local f = u / M.duty
    return M.stand + M.lift * math.sin(math.pi * f), s * stride * (2 * f - 1)
  end
  local f = (u - M.duty) / (1 - M.duty)
  return M.stand, s * stride * (1 - 2 * f)
end

--- The heading (rad) of a link's x axis from its orientation quaternion {w, x, y, z}.
function M.heading(q)
  local w, x, y, z = q[1], q[2], q[3], q[4]
  return math.atan(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))
end

--- An angle wrapped into [-pi, pi).
function M.wrap(a)
  return (a + math.pi) % (2 * math.pi) - math.pi
end

return M
