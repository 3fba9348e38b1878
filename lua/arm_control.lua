-- Pieces shared by the arm controllers (behaviors/arm_ik.lua, behaviors/arm_grows.lua): the
-- newest-record merge of flooded joint angles, the adaptive damping and the limit-aware damped
-- least-squares step, and the integrated servo command.
local linalg = require("linalg")

local M = {}

M.step_gain = 0.1  -- fraction of the DLS step added to the command per control step
M.windup = 0.15    -- rad: farthest the command may run ahead of the measured angle
M.max_rate = 0.3   -- rad/s: fastest a command moves (the arm's inertia at the servos' torque)

local function clamp(x, lo, hi) return math.max(lo, math.min(hi, x)) end

--- Keeps, per module name, the newest record ({t = time, ...}) of `into` and `from`.
function M.merge(into, from)
  for name, rec in pairs(from or {}) do
    local have = into[name]
    if not have or rec.t > have.t then into[name] = rec end
  end
end

--- Damping for a DLS step from a 3-row tip Jacobian's smallest singular value
--- (Maciejewski/Nakamura): lambda_min always, growing towards lambda_max as it falls below zone.
function M.damping(J, lambda_min, lambda_max, zone)
  local _, sv = linalg.matrix(J):svd()
  local smin = sv:get(3)
  local l2 = lambda_min ^ 2
  if smin < zone then l2 = l2 + (1 - (smin / zone) ^ 2) * lambda_max ^ 2 end
  return math.sqrt(l2)
end

--- The damped least-squares step dq of A dq = b; joints the step would push past [lo, hi] are
--- taken out and the step solved again (three passes at most).
function M.solve_within(A, b, lambda, q, lo, hi)
  local n = A:cols()
  local dq, free = nil, {}
  for i = 1, n do free[i] = true end
  for pass = 1, 3 do
    local Aw = A
    if pass > 1 then
      Aw = A:copy()
      for i = 1, n do
        if not free[i] then for r = 1, Aw:rows() do Aw:set(r, i, 0) end end
      end
    end
    dq = Aw:dls(b, lambda)
    local again = false
    for i = 1, n do
      local v = q[i] + dq:get(i)
      if free[i] and (v > hi[i] or v < lo[i]) then free[i], again = false, true end
    end
    if not again then break end
  end
  return dq
end

--- The next servo command: the previous one (or the measured angle q) plus step_gain of the DLS
--- step, at most max_rate * dt, within windup of q and within [lo, hi]. Because the step comes
--- from the measured pose, whatever the servos leave undone (sag, latency) keeps moving the
--- command until the measured tip is on target.
function M.command(prev, q, step, lo, hi, dt)
  local rate = M.max_rate * dt
  local c = (prev or q) + clamp(M.step_gain * step, -rate, rate)
  return clamp(clamp(c, q - M.windup, q + M.windup), lo, hi)
end

return M
