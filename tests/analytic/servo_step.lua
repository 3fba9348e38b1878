-- Analytic check: a SuperBot servo's 45 degree step is reached within 2 degrees in 1 s, on each
-- joint (pitch, roll, yaw), for a module fixed in space and for one lying on the ground. The
-- motor's speed limit (3 rad/s) alone would take 0.26 s; the rest is the servo's approach (gain
-- 20/s). Logged: when each joint first came within 2 degrees, its largest overshoot, and its angle
-- at 1 s. `--param solver=pgs` runs it on the old solver.
if args.solver then world.set{solver = args.solver} end
world.set{duration = 1.1}
world.ground{}
local target = math.rad(45)
local cases = {}
for k, j in ipairs({"pitch", "roll", "yaw"}) do
  for _, fixed in ipairs({true, false}) do
    local at = fixed and {k * 0.5, 1, 1} or {k * 0.5, 0, 0.043}
    cases[#cases + 1] = {
      joint = j, fixed = fixed, within = nil, over = 0,
      m = world.spawn("superbot", {at = at, fixed = fixed, behavior = "behaviors/hold.lua",
                                   params = {targets = {[j] = target}}}),
    }
  end
end
world.on_step(function(t)
  for _, c in ipairs(cases) do
    local a = c.m:joint_angle(c.joint)
    if not c.within and math.abs(a - target) < math.rad(2) then c.within = t end
    c.over = math.max(c.over, a - target)
  end
end)
world.at(1.0, function()
  for _, c in ipairs(cases) do
    local deg = math.deg(c.m:joint_angle(c.joint))
    local where = c.fixed and "fixed in space" or "on the ground"
    log(string.format("%-5s %-14s within 2 deg at %s s, overshoot %.2f deg, %.3f deg at 1 s", c.joint, where,
                      c.within and string.format("%.3f", c.within) or "never", math.deg(math.max(0, c.over)), deg))
    expect(math.abs(deg - 45) < 2,
           string.format("%s (%s) at %.2f deg after 1 s, expected 45 +- 2", c.joint, where, deg))
  end
end)
