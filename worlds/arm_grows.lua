-- The growing arm (the paper's Fig. 5, top): a short SuperBot arm (two SuperBots joined by an
-- elongated dock, 6 joints) hangs from a fixed base (an elongated dock on a gantry). A free
-- SuperBot waits below, docked by its `front` to a fixed station (an elongated dock on a pillar),
-- its `back` dock facing up; it lets go of the station as the arm's dock arrives (its own
-- proximity reading). The arm does not know where it is: it finds it by
-- its tip dock's proximity reading, trilaterates the free dock from the readings, brings its tip
-- onto it with IK, latches by magnet, takes the newcomer's three joints into its model (9 joints)
-- and reaches a goal farther from the base than the short arm can reach (behaviors/arm_grows.lua).
--
--   rm3d run worlds/arm_grows.lua
--
-- Checks at the end: the goal is beyond the short arm's reach; the grown arm's tip ends within
-- 3 mm of it; the free module is docked to the arm's tip and lifted off its station; no dock
-- broke; no module faulted. Metrics: found_at_s, docked_at_s, dock_estimate_error_mm,
-- goal_error_mm, short_reach_m, goal_distance_m.
local kDuration = 24
world.set{solver = "exact", duration = kDuration}
world.ground{}

local kTop = 0.9                 -- m: the base's lower dock face (the arm hangs from it)
local kHang = { math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0 }  -- module x axis down, z along +x
local free = { 0.105, 0 }        -- where the free module stands (the arm does not know)
local goal = { -0.08, 0.06, kTop - 0.56 }

-- The gantry: a beam the base hangs from, on a post.
world.box{ size = { 0.5, 0.08, 0.04 }, at = { -0.17, 0, kTop + 0.12 } }
world.box{ size = { 0.08, 0.08, kTop + 0.1 }, at = { -0.38, 0, (kTop + 0.1) / 2 } }

local layout = {
  { "base", "elongated_dock" },
  { "sb1", "superbot", "front", "back" },
  { "link1", "elongated_dock", "front", "back" },
  { "sb2", "superbot", "front", "back" },
}
local structure = { modules = {}, connections = {}, base = "base",
                    base_pose = { at = { 0, 0, kTop + 0.05 }, quat = kHang } }
for i, m in ipairs(layout) do
  structure.modules[i] = { name = m[1], type = m[2] }
  if i > 1 then structure.connections[#structure.connections + 1] = { layout[i - 1][1], m[3], m[1], m[4], 0 } end
end
local params = { structure = structure, controller = "sb2", start = 0.5, lattice_up = { 1, 0, 0 },
                 search = { center = { 0, 0 }, radii = { 0.16, 0.11, 0.06 }, start = math.pi },
                 goal = goal, lift = 0.06, lift_time = 3 }
local mods = {}
for i, m in ipairs(layout) do
  mods[i] = world.spawn(m[2], { name = m[1], fixed = (i == 1), at = i == 1 and structure.base_pose.at or nil,
                                quat = i == 1 and kHang or nil, behavior = "behaviors/arm_grows.lua", params = params })
  if i > 1 then world.connect(mods[i - 1], m[3], mods[i], m[4]) end
end
world.camera{ eye = { 0.75, -1.45, 0.8 }, target = { 0, 0, 0.55 }, fov = 45 }

-- What the short arm could reach: its tip's distance from the base's dock face, straight (the
-- longest a chain of straight segments gets).
local kin = require("kinematics")
local kmods = {}
for i, m in ipairs(structure.modules) do kmods[i] = { name = m.name, type = world.module_type(m.type) } end
local short = kin.structure{ modules = kmods, connections = structure.connections, base = "base",
                             base_pose = structure.base_pose }
local q0 = {}
for i = 1, #short.dofs do q0[i] = 0 end
local face = short:fk(q0):dock("base", "front")
local reach = math.sqrt((face[1] - short:fk(q0):dock("sb2", "front")[1]) ^ 2
                        + (face[2] - short:fk(q0):dock("sb2", "front")[2]) ^ 2
                        + (face[3] - short:fk(q0):dock("sb2", "front")[3]) ^ 2)
local goalDistance = math.sqrt((goal[1] - face[1]) ^ 2 + (goal[2] - face[2]) ^ 2 + (goal[3] - face[3]) ^ 2)

-- The station's height: the free dock 2 mm below where the short arm's tip, pointing down with
-- its twist on the lattice, can be over it (pointing down, a hanging arm of two bending joints a
-- plane reaches each x, y at one height, higher the farther out; the arm comes in from outside,
-- from higher, and ends with its face on the free one). Found from the model by damped least
-- squares on the world side.
local function restHeight(x, y)
  local q = {}
  for i = 1, #short.dofs do q[i] = 0 end
  local d = short.modules.sb2.dock("front")
  local at, nrm, up = { d.at[1] or d.at.x, d.at[2] or d.at.y, d.at[3] or d.at.z },
                      { d.normal[1] or d.normal.x, d.normal[2] or d.normal.y, d.normal[3] or d.normal.z },
                      { d.up[1] or d.up.x, d.up[2] or d.up.y, d.up[3] or d.up.z }
  local linalg = require("linalg")
  local p
  for _ = 1, 400 do
    local f = short:fk(q)
    local J
    J, p = f:jacobian("sb2", "front")
    local rows, rhs = { J[1], J[2] }, { x - p[1], y - p[2] }
    for _, pair in ipairs({ { nrm, { 0, 0, -1 } }, { up, { 1, 0, 0 } } }) do
      local Jk, pk = f:jacobian("sb2", "front", { at[1] + 0.05 * pair[1][1], at[2] + 0.05 * pair[1][2], at[3] + 0.05 * pair[1][3] })
      for r = 1, 3 do
        rows[#rows + 1] = Jk[r]
        rhs[#rhs + 1] = p[r] + 0.05 * pair[2][r] - pk[r]
      end
    end
    local dq = linalg.matrix(rows):dls(linalg.vector(rhs), 0.005)
    for i = 1, #q do q[i] = q[i] + 0.5 * dq:get(i) end
  end
  return p[3]
end
local kStation = restHeight(free[1], free[2]) - 0.002 - 0.19  -- the station's top face


-- The free module waits docked by its front to a fixed station (an elongated dock on end, on a
-- pillar) with its back dock facing up; once the arm has latched on, it lets go of the station.
local kUp = { math.cos(-math.pi / 4), 0, math.sin(-math.pi / 4), 0 }  -- module x axis up
local station = world.spawn("elongated_dock", { name = "station", fixed = true, quat = kUp,
                                                at = { free[1], free[2], kStation - 0.05 } })
world.box{ size = { 0.08, 0.08, kStation - 0.1 }, at = { free[1], free[2], (kStation - 0.1) / 2 } }
local newcomer = world.spawn("superbot", {
  name = "sb3", at = { free[1], free[2], kStation + 0.095 }, quat = kHang,
  behavior = "behaviors/arm_grows.lua", params = { free = true, offer = "back", release = "front" },
})
world.connect(station, "front", newcomer, "front", 2)

local docked_at, estErr, estErrXY
local waiting = newcomer:dock_position("back") -- where the free dock waits, before anything moves
world.on_step(function(t)
  if not docked_at and mods[4]:dock_state("front").engaged then
    docked_at = t
    -- How far the arm's estimate of the free dock (from its proximity readings) was from where
    -- it waited.
    local est, truth = mods[4]:published("estimate"), waiting
    estErr = est and math.sqrt((est[1] - truth.x) ^ 2 + (est[2] - truth.y) ^ 2 + (est[3] - truth.z) ^ 2)
    estErrXY = est and math.sqrt((est[1] - truth.x) ^ 2 + (est[2] - truth.y) ^ 2)
  end
end)

world.on_end(function(t)
  local tip = newcomer:dock_position("front")
  local err = math.sqrt((tip.x - goal[1]) ^ 2 + (tip.y - goal[2]) ^ 2 + (tip.z - goal[3]) ^ 2)
  local found = mods[4]:published("found_at")
  local broken = 0
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken = broken + 1 end
  end
  local st = mods[4]:dock_state("front")
  world.metric("short_reach_m", reach)
  world.metric("goal_distance_m", goalDistance)
  world.metric("goal_error_mm", err * 1000)
  if found then world.metric("found_at_s", found) end
  if docked_at then world.metric("docked_at_s", docked_at) end
  if estErr then
    world.metric("dock_estimate_error_mm", estErr * 1000)
    world.metric("dock_estimate_error_xy_mm", estErrXY * 1000)
  end
  print(string.format("arm_grows: found at %s s, docked at %s s (dock estimated %s mm off, %s mm across), %d joints; goal %.3f m from"
                      .. " the base (short arm reaches %.3f m), tip %.2f mm from it; newcomer %.3f m above its station",
                      tostring(found), tostring(docked_at), estErr and string.format("%.2f", estErr * 1000) or "-",
                      estErrXY and string.format("%.2f", estErrXY * 1000) or "-",
                      mods[4]:published("dofs") or 0, goalDistance, reach, err * 1000,
                      newcomer:position().z - 0.095 - kStation))
  for _, m in ipairs(mods) do expect(m:error() == nil, m.name .. " did not fault: " .. tostring(m:error())) end
  expect(newcomer:error() == nil, "sb3 did not fault: " .. tostring(newcomer:error()))
  if t < kDuration then return end -- a shorter run (the sample test's 2 s) checks only the faults
  expect(goalDistance > reach + 0.03, string.format("the goal (%.3f m from the base) is beyond the short arm's reach (%.3f m)",
                                                    goalDistance, reach))
  expect(st.engaged and st.peer_module == newcomer.id and st.peer_dock == "back",
         "the free module is docked to the arm's tip by its back dock")
  expect(mods[4]:published("dofs") == 9, "the controller's model has 9 joints, got " .. tostring(mods[4]:published("dofs")))
  expect(err < 0.003, string.format("the grown arm's tip ended %.2f mm from the goal, expected < 3 mm", err * 1000))
  expect(newcomer:position().z - 0.095 - kStation > 0.02, "the newcomer was lifted off its station")
  expect(broken == 0, broken .. " dock connections broke")
end)
