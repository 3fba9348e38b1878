-- lua/kinematics.lua's static loads against the physics: the arm of worlds/arm_ik.lua (three
-- SuperBots and two elongated docks on a fixed base), posed at random angles from the seed under
-- gravity on the exact solver (behaviors/hold.lua). Once still, each servo's torque
-- (m:joint_torque) must equal the model's static torque at the measured angles, and each dock's
-- load (m:dock_load) the model's, within 2% of the largest plus 0.005 N m (0.05 N for forces).
-- The same check also runs the Jacobian against finite differences of the forward kinematics.
local kin = require("kinematics")
local arm = require("arm_ik_world")
world.set{solver = "exact", duration = 2.1}
local model = arm.model()
-- a pose the servos hold comfortably (the arm world's own feasibility rule)
local q
repeat
  q = {}
  for i = 1, #model.dofs do q[i] = (2 * math.random() - 1) * 0.5 end
  local tau = model:gravity(q)
  local ok = true
  for i, d in ipairs(model.dofs) do
    if math.abs(tau[i]) > 0.3 * d.torque then ok = false end
  end
until ok
local targets = {}
for i, d in ipairs(model.dofs) do
  targets[d.module] = targets[d.module] or {}
  targets[d.module][d.joint] = q[i]
end
local mods = {}
for i, m in ipairs(arm.layout) do
  mods[i] = world.spawn(m[2], {name = m[1], fixed = (i == 1), at = i == 1 and arm.base_at or nil,
                              quat = i == 1 and arm.base_quat or nil, behavior = "behaviors/hold.lua",
                              params = {targets = targets[m[1]] or {}}})
  if i > 1 then world.connect(mods[i - 1], arm.layout[i][3], mods[i], arm.layout[i][4]) end
end

world.at(2.0, function()
  local measured = {}
  for i, m in ipairs(mods) do measured[arm.layout[i][1]] = m:joint_angles() end
  local qm = model:angles_from(measured)
  local tau, loads = model:gravity(qm)
  local byName = {}
  for i, m in ipairs(mods) do byName[arm.layout[i][1]] = m end
  local worstT, largestT = 0, 0
  for i, d in ipairs(model.dofs) do
    local sim = byName[d.module]:joint_torque(d.joint)
    worstT = math.max(worstT, math.abs(math.abs(sim) - math.abs(tau[i])))
    largestT = math.max(largestT, math.abs(tau[i]))
  end
  local worstF, worstM, largestF, largestM = 0, 0, 0, 0
  for c = 1, #loads do
    local l = mods[c]:dock_load("front")
    worstF = math.max(worstF, math.abs(l.force - loads[c].force))
    worstM = math.max(worstM, math.abs(l.torque - loads[c].torque))
    largestF, largestM = math.max(largestF, loads[c].force), math.max(largestM, loads[c].torque)
  end
  log(string.format("static torques: worst %.4f N m off (largest %.3f N m); dock loads: worst %.4f N, %.4f N m off"
                    .. " (largest %.2f N, %.3f N m)", worstT, largestT, worstF, worstM, largestF, largestM))
  expect(largestT > 0.1, "the pose loads the servos")
  expect(worstT < 0.02 * largestT + 0.005, string.format("servo torques off the model by %.4f N m", worstT))
  expect(worstF < 0.02 * largestF + 0.05, string.format("dock forces off the model by %.4f N", worstF))
  expect(worstM < 0.02 * largestM + 0.005, string.format("dock torques off the model by %.4f N m", worstM))
  -- Jacobian against finite differences of the tip position
  local f = model:fk(qm)
  local J, p = f:jacobian(arm.tip[1], arm.tip[2])
  local worstJ = 0
  for j = 1, #qm do
    local qq = {}
    for k = 1, #qm do qq[k] = qm[k] end
    qq[j] = qq[j] + 1e-6
    local p2 = model:fk(qq):dock(arm.tip[1], arm.tip[2])
    for r = 1, 3 do worstJ = math.max(worstJ, math.abs((p2[r] - p[r]) / 1e-6 - J[r][j])) end
  end
  expect(worstJ < 1e-5, string.format("Jacobian off finite differences by %.2e", worstJ))
end)
