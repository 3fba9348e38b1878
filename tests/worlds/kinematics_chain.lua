-- lua/kinematics.lua against the simulation: a fixed elongated dock carries a chain of SuperBots
-- and another elongated dock, joined by several docks (front, back, left, up) and mating
-- orientations, posed at random joint angles from the seed (behaviors/hold.lua), on the exact
-- solver without gravity. After the servos settle, the forward kinematics of the measured joint
-- angles must give every link's simulated pose within 0.1 mm and 0.1 degree.
world.set{solver = "exact", gravity = {0, 0, 0}, duration = 1.6}
local kin = require("kinematics")

local layout = {   -- module, type, and how it hangs on the one before
  {"base", "elongated_dock"},
  {"sb1", "superbot", "front", "back", 0},
  {"bar", "elongated_dock", "front", "back", 1},
  {"sb2", "superbot", "front", "back", 2},
  {"sb3", "superbot", "left", "up", 3},
  {"sb4", "superbot", "front", "down", 1},
}
local mods, kmods, conns = {}, {}, {}
local base_at, base_quat = {0.1, -0.2, 0.6}, {math.cos(0.3), 0, math.sin(0.3), 0}
for i, m in ipairs(layout) do
  local name, typ = m[1], m[2]
  local targets = {}
  if typ == "superbot" then
    for _, j in ipairs({"pitch", "roll", "yaw"}) do targets[j] = (math.random() * 2 - 1) * 1.2 end
  end
  mods[i] = world.spawn(typ, {name = name, behavior = "behaviors/hold.lua", params = {targets = targets},
                              fixed = (i == 1), at = i == 1 and base_at or nil, quat = i == 1 and base_quat or nil})
  kmods[i] = {name = name, type = world.module_type(typ)}
  if i > 1 then
    world.connect(mods[i - 1], m[3], mods[i], m[4], m[5])
    conns[#conns + 1] = {layout[i - 1][1], m[3], name, m[4], m[5]}
  end
end
local s = kin.structure{modules = kmods, connections = conns, base = "base",
                        base_pose = {at = base_at, quat = base_quat}}
expect(#s.dofs == 12, "12 joints in the chain, got " .. #s.dofs)

local function angleBetween(q1, q2)
  local d = math.abs(q1[1] * q2[1] + q1[2] * q2[2] + q1[3] * q2[3] + q1[4] * q2[4])
  return 2 * math.acos(math.min(1, d))
end

world.at(1.5, function()
  local measured = {}
  for i, m in ipairs(mods) do measured[layout[i][1]] = m:joint_angles() end
  local f = s:fk(s:angles_from(measured))
  local worstPos, worstAng, where = 0, 0, ""
  local posed = 0
  for i, m in ipairs(mods) do
    for name, a in pairs(m:joint_angles()) do posed = math.max(posed, math.abs(a)) end
    for _, link in ipairs(kmods[i].type.links) do
      local p, q = m:link_pose(link.name)
      local fp, fq = f:link_pose(layout[i][1], link.name)
      local dp = math.sqrt((p.x - fp[1]) ^ 2 + (p.y - fp[2]) ^ 2 + (p.z - fp[3]) ^ 2)
      local da = angleBetween({q.w, q.x, q.y, q.z}, fq)
      if dp > worstPos then worstPos, where = dp, layout[i][1] .. "." .. link.name end
      worstAng = math.max(worstAng, da)
    end
  end
  log(string.format("FK vs simulation over 16 links: worst %.4f mm (%s), %.4f deg; joints posed up to %.1f deg",
                    worstPos * 1000, where, math.deg(worstAng), math.deg(posed)))
  expect(posed > math.rad(20), "the chain is posed away from zero")
  expect(worstPos < 1e-4, string.format("FK position off by %.4f mm at %s, expected < 0.1 mm", worstPos * 1000, where))
  expect(worstAng < math.rad(0.1), string.format("FK rotation off by %.4f deg, expected < 0.1 deg", math.deg(worstAng)))
  -- the dock the next module hangs on, through the Jacobian's point
  local J, p = f:jacobian("sb4", "front")
  local dp = mods[6]:dock_position("front")
  expect(math.abs(p[1] - dp.x) + math.abs(p[2] - dp.y) + math.abs(p[3] - dp.z) < 3e-4, "jacobian point = dock centre")
  expect(#J == 3 and #J[1] == 12, "3 x 12 Jacobian")
end)

-- The type data carries the servo's data too (SuperBot: 2.5 N m, gain 20, stiffness 300 N m/rad).
local sb = world.module_type("superbot").joints[1]
expect(sb.torque == 2.5 and sb.gain == 20 and sb.stiffness == 300,
       string.format("superbot joint data: torque %s, gain %s, stiffness %s", sb.torque, sb.gain, sb.stiffness))
